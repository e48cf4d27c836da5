/* Fresnel, Multiscatter GGX and the diffuse under a dielectric layer as colour factors at the pixel's view
 * (reflectance/layering.py explains the forms; `factors` there is this file's numpy mirror).  Needs the
 * scene and material blocks and the layering_table sampler (E, E_w, E_avg over cos theta_o x roughness).
 * LAYERING_FRESNEL: Schlick on the specular colour; LAYERING_MULTISCATTER: the multiscatter gain; the
 * diffuse is layered when material.diffuse_color.w (the layer's F0) is not negative. */

/* The colour on the engine's GGX lobe: Schlick's average over the lobe from f0 (or f0 itself), times the
 * multiscatter gain */
vec3 layering_specular_colour(vec3 f0, vec3 table, bool fresnel)
{
  float albedo = max(table.x, 1.0e-4);
  vec3 single = f0;
  vec3 fresnel_average = f0;
  if (fresnel) {
    single = (f0 * (albedo - table.y) + table.y) / albedo;
    fresnel_average = f0 + (vec3(1.0) - f0) * LAYERING_SCHLICK_AVERAGE;
  }
#ifdef LAYERING_MULTISCATTER
  fresnel_average = min(fresnel_average, vec3(1.0));
  vec3 multiple = fresnel_average * table.z / max(vec3(1.0) - fresnel_average * (1.0 - table.z), vec3(1.0e-4));
  single *= vec3(1.0) + multiple * (1.0 - albedo) / albedo;
#endif
  return single;
}

/* The view's cosine to the shading normal, the layer's roughness (material.options.z, times the roughness
 * texture when the model is GGX: LAYERING_TEXTURED_ROUGHNESS) */
void surface_layering(vec3 shading_normal, inout vec3 diffuse_color, inout vec3 specular_color)
{
  vec3 view = scene.camera.w > 0.5 ? normalize(scene.camera.xyz - world_position) : -normalize(scene.camera.xyz);
  float roughness = material.options.z;
#ifdef LAYERING_TEXTURED_ROUGHNESS
  roughness *= texture_value_roughness().r;
#endif
  vec2 coords = (clamp(vec2(dot(shading_normal, view), roughness), 0.0, 1.0) * float(LAYERING_TABLE_SIZE - 1) + 0.5) /
                float(LAYERING_TABLE_SIZE);
  vec3 table = texture(layering_table, coords).rgb;
#ifdef LAYERING_FRESNEL
  specular_color = layering_specular_colour(specular_color, table, true);
#else
  specular_color = layering_specular_colour(specular_color, table, false);
#endif
  float layer_f0 = material.diffuse_color.w;
  if (layer_f0 >= 0.0) {
    float reflected = clamp(layering_specular_colour(vec3(layer_f0), table, true).x * table.x, 0.0, 1.0);
    diffuse_color *= 1.0 - reflected;
  }
}
