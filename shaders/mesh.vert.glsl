/* Object-space corners -> world space; the fragment shader shades in world space. */
void main()
{
  vec4 world = model_matrix * vec4(position, 1.0);
  mat3 linear = mat3(model_matrix);
  world_position = world.xyz;
  world_normal = transpose(inverse(linear)) * normal;
  /* a mirroring transform flips n x t: keep the bitangent on the UV side */
  float handedness = determinant(linear) < 0.0 ? -1.0 : 1.0;
  world_tangent = vec4(linear * tangent.xyz, tangent.w * handedness);
  texcoord = uv;
  gl_Position = view_projection * world;
}
