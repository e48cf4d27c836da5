/* The broad diffuse lobes' visibility at the mesh vertices, for the surface shader to interpolate
 * (DIFFUSE_VISIBILITY_ROWS; mirrored by techniques.sg_shading.vertex_diffuse_visibility).  One texel = four lobes
 * of one vertex, laid out like the coefficient texture: vertex v's row r at texel
 * ((v % per_row) * DIFFUSE_VISIBILITY_ROWS + r, v / per_row), per_row = coefficient texels a row /
 * SSDF_MAX_LAYERS.  The lobes: the environment's SG mixture (HAS_ENVIRONMENT), else the constant world's
 * cosine lobe.  Their products with the cosine lobe are broad (the diffuse fit's lobes), so the
 * fraction varies slowly across a triangle: a vertex's decodes cost what a pixel's do, and a mesh has
 * far fewer vertices than the pixels it covers.  The vertex normal stands in for the shading normal
 * in the product (the cosine integral itself stays per pixel). */
void main()
{
  ivec2 texel = ivec2(gl_FragCoord.xy);
  int slot = texel.x / DIFFUSE_VISIBILITY_ROWS;             /* the vertex within its texture row */
  int first_lobe = 4 * (texel.x - slot * DIFFUSE_VISIBILITY_ROWS);
  for (int layer = 0; layer < SSDF_MAX_LAYERS; layer++) {
    visibility_rows[layer] = texelFetch(visibility_coefficients, ivec2(slot * SSDF_MAX_LAYERS + layer, texel.y), 0);
  }
  vec3 normal = transpose(inverse(mat3(model_matrix))) * texelFetch(vertex_normals, ivec2(slot, texel.y), 0).xyz;
  set_visibility_frame(normal);
  vec3 n = safe_normalize(normal);
  vec4 fractions = vec4(1.0);
#ifdef HAS_ENVIRONMENT
  for (int j = 0; j < 4; j++) {
    int e = first_lobe + j;
    if (e < scene.counts.z) {
      fractions[j] = lobe_visibility(scene.env_axis_sharpness[e].xyz, scene.env_axis_sharpness[e].w, n);
    }
  }
#else
  fractions.x = lobe_visibility(n, 0.0, n);
#endif
  out_fractions = fractions;
}
