/* What every surface technique's main() reads and writes around its shading: the normal facing the viewer's
 * side, the material's colours, the tangent input with the shading normal and tangent, and the passes.
 * Needs surface_common.glsl (apply_normal_map, rotate_tangent), material_textures.glsl and the slots'
 * texture_value_<slot>() (techniques/material_textures.py), the material block, the surface's varyings and
 * outputs (techniques/shader_sources.py surface_calls) and the normal-map sampler HAS_NORMAL_MAP names. */

/* A mirroring transform (negative determinant) reverses the triangles' winding: its front faces face away. */
vec3 surface_facing_normal()
{
  bool front = gl_FrontFacing != (determinant(mat3(model_matrix)) < 0.0);
  return front ? world_normal : -world_normal;
}

/* The surface's coverage (a node tree's transparency, reflectance/coverage.py) as dithered samples: a sample
 * keeps the surface where the alpha exceeds its threshold.  Interleaved gradient noise spreads the thresholds
 * over [0, 1) across neighbouring pixels, and each jittered frame moves them by its own offset
 * (scene.shading_footprint.w), so a pixel's Render Samples converge to alpha x surface + (1 - alpha) x what is
 * behind, as Cycles and EEVEE's dithered transparency do.  Call it first: a dropped sample shades nothing. */
void surface_coverage()
{
#ifdef HAS_COVERAGE
  float alpha = material.options.w;
#  ifdef HAS_TEXTURE_ALPHA
  alpha *= texture_value_alpha().r;
#  endif
  float noise = fract(52.9829189 * fract(dot(floor(gl_FragCoord.xy), vec2(0.06711056, 0.00583715))));
  if (alpha <= fract(noise + scene.shading_footprint.w)) {
    discard;
  }
#endif
}

/* The spread of the normal map's normals over the pixel (normal_spread), which widens the NDF lobes
 * (spread_lobe): 0 without a normal map or where it is not minified. */
float normal_map_spread = 0.0;

/* The colours' textures over the active UV map, multiplied onto their base values (the material's, or a
 * stored fit's). */
void surface_colour_textures(inout vec3 diffuse_color, inout vec3 specular_color)
{
#ifdef HAS_TEXTURE_DIFFUSE_COLOR
  diffuse_color *= texture_value_diffuse_color().rgb;
#endif
#ifdef HAS_TEXTURE_SPECULAR_COLOR
  specular_color *= texture_value_specular_color().rgb;
#endif
}

/* The tangent input (the UV map's, or the object axis in world space), the shading normal (normal map, or a
 * node tree's computed normal) and the shading tangent (rotated about it). */
void surface_geometry(vec3 normal, out vec4 tangent, out vec3 shading_normal, out vec3 shading_tangent)
{
  tangent = material.options.x > 0.5 ? vec4(mat3(model_matrix) * material.tangent_axis_rotation.xyz, 1.0)
                                     : world_tangent;
  shading_normal = normal;
#ifdef HAS_NORMAL_MAP
  float level;
  vec3 mapped = material_texture_level(texture_normal_map, level).rgb;
  shading_normal = apply_normal_map(normal, tangent, mapped, material.parameters1.w);
  normal_map_spread = normal_spread(2.0 * mapped - 1.0, level, material.parameters1.w);
#endif
#ifdef HAS_TEXTURE_SHADING_NORMAL
  /* a node tree's normal (a Bump node's, world space), turned to the side the viewer sees */
  vec3 computed = normalize(texture_value_shading_normal().xyz);
  shading_normal = dot(computed, normal) < 0.0 ? -computed : computed;
#endif
  shading_tangent = rotate_tangent(shading_normal, tangent.xyz, material.tangent_axis_rotation.w);
}

/* Combined (with the emission, its texture applied; alpha 1 less the holdout's share), Diffuse, Specular, and the GBUFFER variant's shading inputs
 * for the numpy mirrors (framebuffers take 6 attachments: that variant has no Combined, the CPU sums Diffuse and
 * Specular, without the emission); w: the triangle (index into the mesh's triangle list) and the object (draw
 * order) + 1. */
void surface_write(vec3 diffuse, vec3 specular, vec3 normal, vec4 tangent)
{
#ifndef GBUFFER
  vec3 emission = material.emission.rgb;
#  ifdef HAS_TEXTURE_EMISSION
  emission *= texture_value_emission().rgb;
#  endif
  float alpha = 1.0;
#  ifdef HAS_HOLDOUT
  float holdout = material.emission.w;
#    ifdef HAS_TEXTURE_HOLDOUT
  holdout *= texture_value_holdout().r;
#    endif
  alpha = 1.0 - clamp(holdout, 0.0, 1.0);
#  endif
  out_combined = vec4(diffuse + specular + emission, alpha);
#endif
  out_diffuse = vec4(diffuse, 1.0);
  out_specular = vec4(specular, 1.0);
#ifdef GBUFFER
  out_position = vec4(world_position, float(gbuffer_triangle_offset + gl_PrimitiveID) + 1.0);
  out_normal = vec4(normal, float(gbuffer_object_index) + 1.0);
  out_tangent = tangent;
  /* w: 1 + the textures' footprint, for the mirrors (1 or more: covered) */
  out_uv = vec4(texcoord, material.options.y, 1.0 + texture_footprint());
#endif
}
