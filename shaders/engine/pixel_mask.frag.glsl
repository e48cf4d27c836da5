/* Render Samples, Edges Only (engine/multi_sample.py): drawn at the near plane after the depth pre-pass of a
 * supersampled tile, over every pixel whose image pixel (mask_origin + this pixel / mask_scale) has no pixel of
 * the mask within mask_reach (the pixel filter's reach) in the image, so the surfaces and the world fail the
 * depth test there and are not shaded.  Pixels past the image's border next to an edge are shaded: the filter
 * takes them in, as Cycles' camera rays past the border. */
void main()
{
  ivec2 pixel = mask_origin + ivec2(gl_FragCoord.xy) / mask_scale;
  ivec2 last = textureSize(pixel_mask, 0) - 1;
  for (int dy = -mask_reach; dy <= mask_reach; dy++) {
    for (int dx = -mask_reach; dx <= mask_reach; dx++) {
      ivec2 neighbour = pixel + ivec2(dx, dy);
      if (neighbour == clamp(neighbour, ivec2(0), last) && texelFetch(pixel_mask, neighbour, 0).r > 0.5) {
        discard;
      }
    }
  }
  out_unused = vec4(0.0);
}
