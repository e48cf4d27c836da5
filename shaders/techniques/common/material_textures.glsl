/* A material's images at the surface's texture coordinates: the footprint of a pixel in them, and the mip
 * atlas of an image read trilinear there (spherical/texture_mips.py).  Needs the surface's texcoord varying and
 * the scene block.  techniques/material_textures.py follows it with each textured slot's texture_value_<slot>(). */

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
