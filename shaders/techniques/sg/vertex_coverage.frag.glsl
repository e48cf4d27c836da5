/* The SSDF's quadrature points at the mesh vertices (lib/ssdf_quadrature.glsl), for the pass of the broad
 * diffuse lobes (vertex_visibility.frag.glsl) to weigh: one texel = four points' visible shares (their
 * cells' coverage) of one vertex, laid out like the coefficient texture: vertex v's texel t (points
 * 4t .. 4t + 3) at ((v % per_row) * COVERAGE_TEXELS + t, v / per_row).  Mirrored by
 * techniques.sg.sg_shading.vertex_coverage.  A vertex's points are decoded once here, not once a texel of
 * lobes there. */
void main()
{
  ivec2 texel = ivec2(gl_FragCoord.xy);
  int slot = texel.x / COVERAGE_TEXELS;
  int first_point = 4 * (texel.x - slot * COVERAGE_TEXELS);
  for (int layer = 0; layer < SSDF_MAX_LAYERS; layer++) {
    visibility_rows[layer] = texelFetch(visibility_coefficients, ivec2(slot * SSDF_MAX_LAYERS + layer, texel.y), 0);
  }
  float radius = ssdf_cell_radius();
  vec4 coverage;
  for (int j = 0; j < 4; j++) {
    float theta = ssdf_decode(visibility_basis, visibility_rows, SSDF_MAX_LAYERS, ssdf_quadrature_point(first_point + j));
    coverage[j] = ssdf_cell_coverage(theta, radius);
  }
  out_coverage = coverage;
}
