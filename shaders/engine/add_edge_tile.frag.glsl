/* Render Samples, Edges Only (engine/multi_sample.py): drawn over a tile of the sums (from tile_origin); at the
 * pixels of the edge mask, the filtered value of the tile drawn grid_side times larger with an apron of the
 * pixels the filter reaches: the samples of the pixel and of its neighbours within that reach, each weighted by
 * filter_weights at its x and at its y (engine/pixel_filter.py grid_weights, summing to 1 along an axis).  The
 * sums hold 0 at those pixels (edge_pixels.frag.glsl); elsewhere this adds 0.  Blended ADDITIVE_PREMULT. */
void main()
{
  ivec2 pixel = ivec2(gl_FragCoord.xy);
  vec4 combined = vec4(0.0);
  vec4 diffuse = vec4(0.0);
  vec4 specular = vec4(0.0);
  if (texelFetch(pixel_mask, pixel, 0).r > 0.5) {
    /* the apron puts this pixel's first neighbour (reach pixels before it) at the tile pixel (pixel - origin) */
    ivec2 first = (pixel - tile_origin) * grid_side;
    int count = textureSize(filter_weights, 0).x;
    for (int y = 0; y < count; y++) {
      float weight_y = texelFetch(filter_weights, ivec2(y, 0), 0).r;
      if (weight_y == 0.0) {
        continue;
      }
      for (int x = 0; x < count; x++) {
        float weight = weight_y * texelFetch(filter_weights, ivec2(x, 0), 0).r;
        ivec2 sample_pixel = first + ivec2(x, y);
        combined += weight * texelFetch(frame_combined, sample_pixel, 0);
        diffuse += weight * texelFetch(frame_diffuse, sample_pixel, 0);
        specular += weight * texelFetch(frame_specular, sample_pixel, 0);
      }
    }
  }
  out_combined = combined;
  out_diffuse = diffuse;
  out_specular = specular;
}
