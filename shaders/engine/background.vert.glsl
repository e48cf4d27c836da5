/* One triangle covering the viewport at the far plane. */
void main()
{
  ndc = position;
  gl_Position = vec4(position, 1.0, 1.0);
}
