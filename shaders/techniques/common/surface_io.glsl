/* What every surface technique's main() reads and writes around its shading: the normal facing the viewer's
 * side, the material's colours, the tangent input with the shading normal and tangent, and the passes.
 * Needs surface_common.glsl (apply_normal_map, rotate_tangent), the material block, the surface's varyings
 * and outputs (techniques/shader_sources.py surface_calls) and the colour and normal-map samplers its
 * HAS_TEXTURE_* / HAS_NORMAL_MAP defines name. */

/* A mirroring transform (negative determinant) reverses the triangles' winding: its front faces face away. */
vec3 surface_facing_normal()
{
  bool front = gl_FrontFacing != (determinant(mat3(model_matrix)) < 0.0);
  return front ? world_normal : -world_normal;
}

/* A material texture at the surface's texture coordinates, bilinear and repeating as Blender's Image Texture
 * (the gpu module binds samplers clamped to the edge, so the four texels are fetched here; numpy mirror:
 * techniques.sg.sg_shading.sample_material_texture). */
vec4 material_texture(sampler2D image)
{
  ivec2 size = textureSize(image, 0);
  vec2 position = texcoord * vec2(size) - 0.5;
  vec2 low = floor(position);
  vec2 fraction = position - low;
  ivec2 a = ivec2(low) - size * ivec2(floor(low / vec2(size)));     /* low modulo size, for negative low too */
  ivec2 b = ivec2(a.x + 1 == size.x ? 0 : a.x + 1, a.y + 1 == size.y ? 0 : a.y + 1);
  vec4 bottom = mix(texelFetch(image, a, 0), texelFetch(image, ivec2(b.x, a.y), 0), fraction.x);
  vec4 top = mix(texelFetch(image, ivec2(a.x, b.y), 0), texelFetch(image, b, 0), fraction.x);
  return mix(bottom, top, fraction.y);
}

/* The colours' textures over the active UV map, multiplied onto their base values (the material's, or a
 * stored fit's). */
void surface_colour_textures(inout vec3 diffuse_color, inout vec3 specular_color)
{
#ifdef HAS_TEXTURE_DIFFUSE_COLOR
  diffuse_color *= material_texture(texture_diffuse_color).rgb;
#endif
#ifdef HAS_TEXTURE_SPECULAR_COLOR
  specular_color *= material_texture(texture_specular_color).rgb;
#endif
}

/* The tangent input (the UV map's, or the object axis in world space), the shading normal (normal map) and
 * the shading tangent (rotated about it). */
void surface_geometry(vec3 normal, out vec4 tangent, out vec3 shading_normal, out vec3 shading_tangent)
{
  tangent = material.options.x > 0.5 ? vec4(mat3(model_matrix) * material.tangent_axis_rotation.xyz, 1.0)
                                     : world_tangent;
  shading_normal = normal;
#ifdef HAS_NORMAL_MAP
  shading_normal = apply_normal_map(normal, tangent, material_texture(texture_normal_map).rgb,
                                    material.parameters1.w);
#endif
  shading_tangent = rotate_tangent(shading_normal, tangent.xyz, material.tangent_axis_rotation.w);
}

/* Combined with the emission (summed on the CPU in the G-buffer variant, without it: framebuffers take 6
 * attachments), Diffuse, Specular,
 * and the GBUFFER variant's shading inputs for the numpy mirrors; w: the triangle (index into the mesh's
 * triangle list) and the object (draw order) + 1. */
void surface_write(vec3 diffuse, vec3 specular, vec3 normal, vec4 tangent)
{
#ifndef GBUFFER
  out_combined = vec4(diffuse + specular + material.emission.rgb, 1.0);
#endif
  out_diffuse = vec4(diffuse, 1.0);
  out_specular = vec4(specular, 1.0);
#ifdef GBUFFER
  out_position = vec4(world_position, float(gbuffer_triangle_offset + gl_PrimitiveID) + 1.0);
  out_normal = vec4(normal, float(gbuffer_object_index) + 1.0);
  out_tangent = tangent;
  out_uv = vec4(texcoord, material.options.y, 1.0);
#endif
}
