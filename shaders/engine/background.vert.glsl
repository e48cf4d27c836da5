/* One triangle covering the viewport, at the far plane (FULL_SCREEN_DEPTH 1) or the near one (-1). */
void main()
{
  ndc = position;
  gl_Position = vec4(position, FULL_SCREEN_DEPTH, 1.0);
}
