/* Render Samples, Edges Only (engine/multi_sample.py): from the frame shaded at the pixels' centres, the pixels
 * the jittered frames shade (out_mask 1: the pixel's colour or alpha differs from a neighbour's; mirror:
 * anti_aliasing.edge_pixels), and the sums' first values: 0 there (the jittered frames add theirs), the centred
 * frame elsewhere. */
vec4 finite_or_zero(vec4 value)
{
  return any(isnan(value)) || any(isinf(value)) ? vec4(0.0) : value;
}

bool pixels_differ(vec4 a, vec4 b)
{
  vec3 difference = abs(a.rgb - b.rgb);
  float brighter = max(max(max(a.r, a.g), a.b), max(max(b.r, b.g), b.b));
  return max(max(difference.r, difference.g), difference.b) > edge_threshold * (brighter + edge_floor) ||
         abs(a.a - b.a) > edge_threshold;
}

void main()
{
  ivec2 pixel = ivec2(gl_FragCoord.xy);
  ivec2 last = textureSize(frame_combined, 0) - 1;
  vec4 raw = texelFetch(frame_combined, pixel, 0);
  vec4 centre = finite_or_zero(raw);
  bool edge = any(isnan(raw)) || any(isinf(raw));
  for (int dy = -1; dy <= 1; dy++) {
    for (int dx = -1; dx <= 1; dx++) {
      ivec2 neighbour = pixel + ivec2(dx, dy);
      /* past the image's border there is no neighbour (not a copy of the border pixel) */
      if (neighbour != clamp(neighbour, ivec2(0), last)) {
        continue;
      }
      edge = edge || pixels_differ(centre, finite_or_zero(texelFetch(frame_combined, neighbour, 0)));
    }
  }
  out_mask = vec4(edge ? 1.0 : 0.0);
  out_combined = edge ? vec4(0.0) : raw;
  out_diffuse = edge ? vec4(0.0) : texelFetch(frame_diffuse, pixel, 0);
  out_specular = edge ? vec4(0.0) : texelFetch(frame_specular, pixel, 0);
}
