/* Render Samples, every pixel (engine/multi_sample.py): each pixel of the sums adds the jittered frame's pixels
 * around it, each weighted by the pixel filter at its sample's offset from this pixel's centre
 * (pixel_filter.py frame_weights: row 0 along x, row 1 along y, entry reach + k for f(k + offset)).  The frame
 * moved by the offset (x right, y down) shows at a pixel dx to the right and dy up the point dx - offset.x,
 * dy + offset.y from this pixel's centre.  Past the border the border's pixels stand in.  Blended
 * ADDITIVE_PREMULT: every channel adds. */
void main()
{
  ivec2 pixel = ivec2(gl_FragCoord.xy);
  ivec2 last = textureSize(frame_combined, 0) - 1;
  int reach = (textureSize(frame_weights, 0).x - 1) / 2;
  vec4 combined = vec4(0.0);
  vec4 diffuse = vec4(0.0);
  vec4 specular = vec4(0.0);
  for (int dy = -reach; dy <= reach; dy++) {
    /* the filter is even: f(dy + offset.y) is entry reach + dy, f(dx - offset.x) = f(-dx + offset.x) reach - dx */
    float weight_y = texelFetch(frame_weights, ivec2(reach + dy, 1), 0).r;
    for (int dx = -reach; dx <= reach; dx++) {
      float weight = weight_y * texelFetch(frame_weights, ivec2(reach - dx, 0), 0).r;
      ivec2 neighbour = clamp(pixel + ivec2(dx, dy), ivec2(0), last);
      combined += weight * texelFetch(frame_combined, neighbour, 0);
      diffuse += weight * texelFetch(frame_diffuse, neighbour, 0);
      specular += weight * texelFetch(frame_specular, neighbour, 0);
    }
  }
  out_combined = combined;
  out_diffuse = diffuse;
  out_specular = specular;
}
