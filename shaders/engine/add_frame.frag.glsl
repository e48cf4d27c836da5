/* Render Samples (engine/multi_sample.py): each pixel of the sums (drawn over a tile from tile_origin, or the
 * whole image) adds frame_weight times the sum of its grid_side x grid_side pixels of the frame: a jittered
 * frame (side 1), or a tile drawn grid_side times larger.  Blended ADDITIVE_PREMULT: every channel adds. */
void main()
{
  ivec2 first = (ivec2(gl_FragCoord.xy) - tile_origin) * grid_side;
  vec4 combined = vec4(0.0);
  vec4 diffuse = vec4(0.0);
  vec4 specular = vec4(0.0);
  for (int y = 0; y < grid_side; y++) {
    for (int x = 0; x < grid_side; x++) {
      ivec2 pixel = first + ivec2(x, y);
      combined += texelFetch(frame_combined, pixel, 0);
      diffuse += texelFetch(frame_diffuse, pixel, 0);
      specular += texelFetch(frame_specular, pixel, 0);
    }
  }
  out_combined = frame_weight * combined;
  out_diffuse = frame_weight * diffuse;
  out_specular = frame_weight * specular;
}
