/* The lobe source of the parametric SG technique (sg_parametric): the model's own NDF lobes and M_o
 * (sg_models.glsl).  A lobe source gives sg_shading.glsl's stages what they shade with:
 *   lobes_begin(p, q, view_local)              once a pixel, before the slice (it may set p's free slots);
 *   lobes_ndf(k, p, q, view_local, ...)        NDF lobe k, local frame, and its RGB amplitude;
 *   lobes_m_factor(k, ndf_axis, view_local, wi, p, q)   M_o(wi) of lobe k's warped lobes;
 *   DIFFUSE_FACTOR(world_direction), DIFFUSE_ALBEDO      what scales the diffuse term (1: none). */
#define DIFFUSE_FACTOR(world_direction) 1.0
#define DIFFUSE_ALBEDO 1.0

void lobes_begin(inout vec4 p, vec4 q, vec3 view_local)
{
}

#ifdef HAS_SPECULAR
void lobes_ndf(int k, vec4 p, vec4 q, vec3 view_local, out vec3 axis, out float sharpness, out float amplitude,
               out vec3 colour)
{
  model_ndf_lobe(p, q, k, axis, sharpness, amplitude);
  colour = vec3(1.0);
}

float lobes_m_factor(int k, vec3 ndf_axis, vec3 view_local, vec3 wi, vec4 p, vec4 q)
{
  return model_m_factor(view_local, wi, p, q);
}
#endif
