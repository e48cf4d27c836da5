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

/* The texture coordinates' footprint in a pixel: the larger of their screen derivatives, times the side of the
 * square the pixel stands for (the scene block's shading_footprint.z: a cell of a jittered frame's grid; numpy
 * mirror: the G-buffer's uv.w - 1). */
float texture_footprint()
{
  return max(length(dFdx(texcoord)), length(dFdy(texcoord))) * scene.shading_footprint.z;
}

/* texture_footprint as the fragment's first material texture took it, outside any loop: a lobe source may read
 * its textures inside Specular Anti-Aliasing's grid, where derivatives are undefined (-1: not yet taken). */
float surface_footprint = -1.0;

/* Bilinear at the surface's texture coordinates in the mip level of the atlas at origin, of that size, repeating
 * as Blender's Image Texture (the gpu module binds samplers clamped to the edge, so the four texels are fetched
 * here). */
vec4 mip_level_bilinear(sampler2D image, ivec2 origin, ivec2 size)
{
  vec2 position = texcoord * vec2(size) - 0.5;
  vec2 low = floor(position);
  vec2 fraction = position - low;
  ivec2 a = ivec2(low) - size * ivec2(floor(low / vec2(size)));     /* low modulo size, for negative low too */
  ivec2 b = ivec2(a.x + 1 == size.x ? 0 : a.x + 1, a.y + 1 == size.y ? 0 : a.y + 1);
  vec4 bottom = mix(texelFetch(image, origin + a, 0), texelFetch(image, origin + ivec2(b.x, a.y), 0), fraction.x);
  vec4 top = mix(texelFetch(image, origin + ivec2(a.x, b.y), 0), texelFetch(image, origin + b, 0), fraction.x);
  return mix(bottom, top, fraction.y);
}

/* A material texture at the surface's texture coordinates: an atlas of the image's mip levels and, in its last
 * texel, (width, height, levels) (spherical/texture_mips.py, whose sample() mirrors this), trilinear at the level
 * of the fragment's footprint, which `level` returns. */
vec4 material_texture_level(sampler2D image, out float level)
{
  ivec2 atlas = textureSize(image, 0);
  vec4 header = texelFetch(image, atlas - 1, 0);
  ivec2 size0 = ivec2(header.xy + 0.5);
  int count = int(header.z + 0.5);
  if (surface_footprint < 0.0) {
    surface_footprint = texture_footprint();
  }
  float texels = surface_footprint * float(max(size0.x, size0.y));
  level = clamp(log2(max(texels, 1.0e-30)), 0.0, float(count - 1));
  int low = int(floor(level));
  /* level low's rect (texture_mips.level_rect): level 0 at the origin, the others stacked at its right */
  ivec2 origin = ivec2(0);
  ivec2 size = size0;
  for (int index = 0; index < low; index++) {
    origin = ivec2(size0.x, index == 0 ? 0 : origin.y + size.y);
    size = max((size + 1) / 2, ivec2(1));
  }
  vec4 value = mip_level_bilinear(image, origin, size);
  float fraction = level - float(low);
  if (fraction > 0.0) {
    ivec2 next = ivec2(size0.x, low == 0 ? 0 : origin.y + size.y);
    value = mix(value, mip_level_bilinear(image, next, max((size + 1) / 2, ivec2(1))), fraction);
  }
  return value;
}

vec4 material_texture(sampler2D image)
{
  float level;
  return material_texture_level(image, level);
}

/* The spread of the normal map's normals over the pixel (normal_spread), which widens the NDF lobes
 * (spread_lobe): 0 without a normal map or where it is not minified. */
float normal_map_spread = 0.0;

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
  float level;
  vec3 mapped = material_texture_level(texture_normal_map, level).rgb;
  shading_normal = apply_normal_map(normal, tangent, mapped, material.parameters1.w);
  normal_map_spread = normal_spread(2.0 * mapped - 1.0, level, material.parameters1.w);
#endif
  shading_tangent = rotate_tangent(shading_normal, tangent.xyz, material.tangent_axis_rotation.w);
}

/* Combined (with the emission, its texture applied), Diffuse, Specular, and the GBUFFER variant's shading inputs
 * for the numpy mirrors (framebuffers take 6 attachments: that variant has no Combined, the CPU sums Diffuse and
 * Specular, without the emission); w: the triangle (index into the mesh's triangle list) and the object (draw
 * order) + 1. */
void surface_write(vec3 diffuse, vec3 specular, vec3 normal, vec4 tangent)
{
#ifndef GBUFFER
  vec3 emission = material.emission.rgb;
#  ifdef HAS_TEXTURE_EMISSION
  emission *= material_texture(texture_emission).rgb;
#  endif
  out_combined = vec4(diffuse + specular + emission, 1.0);
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
