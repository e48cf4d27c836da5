/* Object-space corners -> world space; the fragment shader shades in world space.
 * HAS_VISIBILITY: the corner's Blender mesh vertex (vertex_index) selects its row of SSDF PCA
 * coefficients in `visibility_coefficients` (SSDF_MAX_LAYERS texels a vertex, vertices packed
 * row after row, renderer.VisibilityBuffers), passed on as varyings: interpolated per pixel.
 * DIFFUSE_VISIBILITY_ROWS: also its broad diffuse lobes' visible fractions (`diffuse_visibility`, the
 * same layout, resources/vertex_visibility.frag.glsl). */
invariant gl_Position;    /* the depth pre-pass (resources/depth.vert.glsl) computes the same */
#ifdef HAS_VISIBILITY
#define SSDF_FETCH(k) texelFetch(visibility_coefficients, ivec2(column + k, row), 0)
#endif
void main()
{
  vec4 world = model_matrix * vec4(position, 1.0);
  mat3 linear = mat3(model_matrix);
  mat3 normal_matrix = transpose(inverse(linear));
  world_position = world.xyz;
  world_normal = normal_matrix * normal;
  /* a mirroring transform flips n x t: keep the bitangent on the UV side */
  float handedness = determinant(linear) < 0.0 ? -1.0 : 1.0;
  world_tangent = vec4(linear * tangent.xyz, tangent.w * handedness);
  texcoord = uv;
#ifdef HAS_VISIBILITY
  world_ssdf_normal = normal_matrix * ssdf_normal;
  int per_row = textureSize(visibility_coefficients, 0).x / SSDF_MAX_LAYERS;
  int row = vertex_index / per_row;
  int column = (vertex_index - row * per_row) * SSDF_MAX_LAYERS;
  ssdf_coefficients_0 = SSDF_FETCH(0);
#if SSDF_MAX_LAYERS > 1
  ssdf_coefficients_1 = SSDF_FETCH(1);
#endif
#if SSDF_MAX_LAYERS > 2
  ssdf_coefficients_2 = SSDF_FETCH(2);
#endif
#if SSDF_MAX_LAYERS > 3
  ssdf_coefficients_3 = SSDF_FETCH(3);
#endif
#if SSDF_MAX_LAYERS > 4
  ssdf_coefficients_4 = SSDF_FETCH(4);
#endif
#if SSDF_MAX_LAYERS > 5
  ssdf_coefficients_5 = SSDF_FETCH(5);
#endif
#if SSDF_MAX_LAYERS > 6
  ssdf_coefficients_6 = SSDF_FETCH(6);
#endif
#if SSDF_MAX_LAYERS > 7
  ssdf_coefficients_7 = SSDF_FETCH(7);
#endif
#if SSDF_MAX_LAYERS > 8
  ssdf_coefficients_8 = SSDF_FETCH(8);
#endif
#if SSDF_MAX_LAYERS > 9
  ssdf_coefficients_9 = SSDF_FETCH(9);
#endif
#if SSDF_MAX_LAYERS > 10
  ssdf_coefficients_10 = SSDF_FETCH(10);
#endif
#if SSDF_MAX_LAYERS > 11
  ssdf_coefficients_11 = SSDF_FETCH(11);
#endif
#ifdef DIFFUSE_VISIBILITY_ROWS
  int diffuse_column = (vertex_index - row * per_row) * DIFFUSE_VISIBILITY_ROWS;
  diffuse_fractions_0 = texelFetch(diffuse_visibility, ivec2(diffuse_column, row), 0);
#if DIFFUSE_VISIBILITY_ROWS > 1
  diffuse_fractions_1 = texelFetch(diffuse_visibility, ivec2(diffuse_column + 1, row), 0);
#endif
#if DIFFUSE_VISIBILITY_ROWS > 2
  diffuse_fractions_2 = texelFetch(diffuse_visibility, ivec2(diffuse_column + 2, row), 0);
#endif
#if DIFFUSE_VISIBILITY_ROWS > 3
  diffuse_fractions_3 = texelFetch(diffuse_visibility, ivec2(diffuse_column + 3, row), 0);
#endif
#endif
#endif
  gl_Position = scene.view_projection * world;
}
