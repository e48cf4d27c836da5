/* The visible fraction of a broad lobe by a quadrature of the SSDF over the hemisphere: GLSL mirror of
 * sg_prt_addon/visibility/broad_lobes.py.  Depends on sg.glsl and hemisphere.glsl.
 *
 *   ssdf_quadrature_point        <- broad_lobes.quadrature_points (one row)
 *   ssdf_cell_radius             <- broad_lobes.cell_radius
 *   ssdf_cell_coverage           <- broad_lobes.cell_coverage
 *   ssdf_quadrature_weight       <- broad_lobes.quadrature_weight
 *
 * The points (SSDF_QUADRATURE_POINTS, equal-area cells of the local upper hemisphere) and the hand-over to
 * eq. 30 come from the module (techniques/sg/sg_lobes.py quadrature_defines); the sums are written where the
 * decoded coverages are read (techniques/sg/vertex_visibility.frag.glsl). */

const float SSDF_GOLDEN_ANGLE = 2.399963229728653;

/* Local direction of quadrature point j: height at its cell's centre, turning by the golden angle. */
vec3 ssdf_quadrature_point(int j)
{
  float z = (float(j) + 0.5) / float(SSDF_QUADRATURE_POINTS);
  float phi = float(j) * SSDF_GOLDEN_ANGLE;
  float r = sqrt(max(1.0 - z * z, 0.0));
  return vec3(r * cos(phi), r * sin(phi), z);
}

/* Angular radius of a disc of one cell's solid angle, 2 pi / SSDF_QUADRATURE_POINTS. */
float ssdf_cell_radius()
{
  return sqrt(2.0 / float(SSDF_QUADRATURE_POINTS));
}

/* Visible share of a quadrature cell (a disc of `radius`) whose centre lies `signed_distance` (+ visible)
 * from a straight boundary. */
float ssdf_cell_coverage(float signed_distance, float radius)
{
  return disc_coverage(signed_distance, radius);
}

/* Weight of the quadrature against eq. 30's reading of a lobe of this sharpness. */
float ssdf_quadrature_weight(float sharpness)
{
  return 1.0 - clamp((sharpness - SSDF_QUADRATURE_SHARPNESS_START) /
                     (SSDF_QUADRATURE_SHARPNESS_END - SSDF_QUADRATURE_SHARPNESS_START), 0.0, 1.0);
}
