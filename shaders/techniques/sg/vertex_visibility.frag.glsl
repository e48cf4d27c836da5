/* The broad diffuse lobes' visibility at the mesh vertices, for the surface shader to interpolate
 * (DIFFUSE_VISIBILITY_ROWS; mirrored by techniques.sg.sg_shading.vertex_diffuse_visibility).  One texel = four lobes
 * of one vertex, laid out like the coefficient texture: vertex v's row r at texel
 * ((v % per_row) * DIFFUSE_VISIBILITY_ROWS + r, v / per_row), per_row = coefficient texels a row /
 * SSDF_MAX_LAYERS.  The lobes: the environment's SG mixture (HAS_ENVIRONMENT), else the constant world's
 * cosine lobe.  A lobe's visible fraction is the quadrature of the SSDF's coverage over the hemisphere
 * (visibility.broad_lobes; the coverage from vertex_coverage.frag.glsl), handing over to eq. 30's reading
 * at the lobe's axis (lobe_visibility) for the sharper lobes the points are too sparse for.  The fraction
 * varies slowly across a triangle: a vertex's work costs what a pixel's would, and a mesh has far fewer
 * vertices than the pixels it covers.  The vertex normal stands in for the shading normal (the cosine
 * integral itself stays per pixel). */

/* The vertex's coverage at each point, and the points and their open coverage (set once a texel, not a lobe) */
float quadrature_coverage[SSDF_QUADRATURE_POINTS];
vec3 quadrature_points[SSDF_QUADRATURE_POINTS];
float quadrature_open[SSDF_QUADRATURE_POINTS];

/* The quadrature's visible fraction of G(i; local_axis, sharpness) i.z (broad_lobes.quadrature_visible_fraction). */
float quadrature_fraction(vec3 local_axis, float sharpness)
{
  float visible = 0.0, open = 0.0;
  for (int j = 0; j < SSDF_QUADRATURE_POINTS; j++) {
    float lobe = exp(sharpness * (dot(quadrature_points[j], local_axis) - 1.0)) * quadrature_points[j].z;
    visible += lobe * quadrature_coverage[j];
    open += lobe * quadrature_open[j];
  }
  return clamp(visible / max(open, 1.0e-30), 0.0, 1.0);
}

#ifdef HAS_ENVIRONMENT
/* An environment lobe's visible fraction: the quadrature's, handing over to eq. 30's for sharper lobes. */
float broad_lobe_visibility(vec3 axis, float sharpness, vec3 n)
{
  float weight = ssdf_quadrature_weight(sharpness);
  float fraction = 0.0;
  if (weight > 0.0) {
    fraction = weight * quadrature_fraction(axis * visibility_frame, sharpness);
  }
  if (weight < 1.0) {
    fraction += (1.0 - weight) * lobe_visibility(axis, sharpness, n);
  }
  return fraction;
}
#endif

void main()
{
  ivec2 texel = ivec2(gl_FragCoord.xy);
  int slot = texel.x / DIFFUSE_VISIBILITY_ROWS;             /* the vertex within its texture row */
  int first_lobe = 4 * (texel.x - slot * DIFFUSE_VISIBILITY_ROWS);
  for (int t = 0; t < SSDF_QUADRATURE_POINTS / 4; t++) {
    vec4 shares = texelFetch(vertex_coverage, ivec2(slot * (SSDF_QUADRATURE_POINTS / 4) + t, texel.y), 0);
    for (int j = 0; j < 4; j++) {
      quadrature_coverage[4 * t + j] = shares[j];
    }
  }
  float radius = ssdf_cell_radius();
  for (int j = 0; j < SSDF_QUADRATURE_POINTS; j++) {
    quadrature_points[j] = ssdf_quadrature_point(j);
    quadrature_open[j] = ssdf_cell_coverage(asin(quadrature_points[j].z), radius);
  }
  vec4 fractions = vec4(1.0);
#ifdef HAS_ENVIRONMENT
  for (int layer = 0; layer < SSDF_MAX_LAYERS; layer++) {
    visibility_rows[layer] = texelFetch(visibility_coefficients, ivec2(slot * SSDF_MAX_LAYERS + layer, texel.y), 0);
  }
  vec3 normal = transpose(inverse(mat3(model_matrix))) * texelFetch(vertex_normals, ivec2(slot, texel.y), 0).xyz;
  set_visibility_frame(normal);
  vec3 n = safe_normalize(normal);
  for (int j = 0; j < 4; j++) {
    int e = first_lobe + j;
    if (e < scene.counts.z) {
      fractions[j] = broad_lobe_visibility(scene.env_axis_sharpness[e].xyz, scene.env_axis_sharpness[e].w, n);
    }
  }
#else
  fractions.x = quadrature_fraction(vec3(0.0, 0.0, 1.0), 0.0);     /* the cosine lobe: about the SSDF's normal */
#endif
  out_fractions = fractions;
}
