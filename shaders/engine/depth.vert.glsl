/* Depth pre-pass (renderer.Renderer.draw): the surface shaders then run once a pixel.
 * Same expressions as mesh.vert.glsl, and gl_Position is invariant in both, so the
 * shading pass meets exactly the depth written here. */
invariant gl_Position;
void main()
{
  vec4 world = model_matrix * vec4(position, 1.0);
  gl_Position = scene.view_projection * world;
}
