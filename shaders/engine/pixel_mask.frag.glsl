/* Render Samples, Edges Only (engine/multi_sample.py): drawn at the near plane after the depth pre-pass of a
 * supersampled tile, over every pixel whose image pixel (mask_origin + this pixel / mask_scale) the mask leaves
 * out or the image does not hold, so the surfaces and the world fail the depth test there and are not shaded. */
void main()
{
  ivec2 pixel = mask_origin + ivec2(gl_FragCoord.xy) / mask_scale;
  bool inside = all(greaterThanEqual(pixel, ivec2(0))) && all(lessThan(pixel, textureSize(pixel_mask, 0)));
  if (inside && texelFetch(pixel_mask, pixel, 0).r > 0.5) {
    discard;
  }
  out_unused = vec4(0.0);
}
