/* A material's images at texture coordinates: the footprint of a pixel in them, and the mip atlas of an image
 * read trilinear there (spherical/texture_mips.py, whose sample() mirrors it), past its edges as the Image
 * Texture's extension says.  Needs the surface's texcoord varying and the scene block.
 * techniques/material_textures.py follows it with each textured slot's texture_value_<slot>(). */

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

/* A texel index past the edge as an Image Texture's extension takes it: 0 REPEAT wraps, 1 EXTEND and 2 CLIP clamp
 * (CLIP's texels past the edge are black: clip_weight), 3 MIRROR reflects every other period
 * (spherical/texture_fetch.py _texel_index) */
ivec2 extended_texel(ivec2 texel, ivec2 size, int extension)
{
  if (extension == 1 || extension == 2) {
    return clamp(texel, ivec2(0), size - 1);
  }
  if (extension == 3) {
    ivec2 period = 2 * size;
    ivec2 folded = texel - period * ivec2(floor(vec2(texel) / vec2(period)));
    return ivec2(folded.x < size.x ? folded.x : period.x - 1 - folded.x,
                 folded.y < size.y ? folded.y : period.y - 1 - folded.y);
  }
  return texel - size * ivec2(floor(vec2(texel) / vec2(size)));
}

/* Bilinear at texture coordinates uv in the mip level of the atlas at origin, of that size (the gpu module binds
 * samplers clamped to the edge, so the four texels are fetched here). */
vec4 mip_level_bilinear(sampler2D image, ivec2 origin, ivec2 size, vec2 uv, int extension)
{
  vec2 position = uv * vec2(size) - 0.5;
  vec2 low = floor(position);
  vec2 fraction = position - low;
  ivec2 a = extended_texel(ivec2(low), size, extension);
  ivec2 b = extended_texel(ivec2(low) + 1, size, extension);
  /* CLIP: a texel past the edge is black */
  vec2 in_a = extension == 2 ? vec2(greaterThanEqual(ivec2(low), ivec2(0))) : vec2(1.0);
  vec2 in_b = extension == 2 ? vec2(lessThan(ivec2(low) + 1, size)) : vec2(1.0);
  vec4 bottom = texelFetch(image, origin + a, 0) * ((1.0 - fraction.x) * in_a.x) +
                texelFetch(image, origin + ivec2(b.x, a.y), 0) * (fraction.x * in_b.x);
  vec4 top = texelFetch(image, origin + ivec2(a.x, b.y), 0) * ((1.0 - fraction.x) * in_a.x) +
             texelFetch(image, origin + b, 0) * (fraction.x * in_b.x);
  return bottom * ((1.0 - fraction.y) * in_a.y) + top * (fraction.y * in_b.y);
}

/* An atlas of an image's mip levels with, in its last texel, (width, height, levels), read trilinear at uv at the
 * level of `footprint` (texture coordinates a pixel covers), which `level` returns. */
vec4 material_texture_trilinear(sampler2D image, vec2 uv, float footprint, int extension, out float level)
{
  ivec2 atlas = textureSize(image, 0);
  vec4 header = texelFetch(image, atlas - 1, 0);
  ivec2 size0 = ivec2(header.xy + 0.5);
  int count = int(header.z + 0.5);
  level = clamp(log2(max(footprint * float(max(size0.x, size0.y)), 1.0e-30)), 0.0, float(count - 1));
  int low = int(floor(level));
  /* level low's rect (texture_mips.level_rect): level 0 at the origin, the others stacked at its right */
  ivec2 origin = ivec2(0);
  ivec2 size = size0;
  for (int index = 0; index < low; index++) {
    origin = ivec2(size0.x, index == 0 ? 0 : origin.y + size.y);
    size = max((size + 1) / 2, ivec2(1));
  }
  vec4 value = mip_level_bilinear(image, origin, size, uv, extension);
  float fraction = level - float(low);
  if (fraction > 0.0) {
    ivec2 next = ivec2(size0.x, low == 0 ? 0 : origin.y + size.y);
    value = mix(value, mip_level_bilinear(image, next, max((size + 1) / 2, ivec2(1)), uv, extension), fraction);
  }
  return value;
}

/* A material texture at the surface's texture coordinates, repeating, at the fragment's footprint. */
vec4 material_texture_level(sampler2D image, out float level)
{
  if (surface_footprint < 0.0) {
    surface_footprint = texture_footprint();
  }
  return material_texture_trilinear(image, texcoord, surface_footprint, 0, level);
}

vec4 material_texture(sampler2D image)
{
  float level;
  return material_texture_level(image, level);
}

/* A material texture at texture coordinates of a node tree's own (a vector into the Image Texture), at their
 * footprint in the pixel, past the edges as `extension` says (CLIP: transparent black outside [0, 1]^2). */
vec4 material_texture_at(sampler2D image, vec2 uv, int extension)
{
  if (extension == 2 && (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0))))) {
    return vec4(0.0);
  }
  float footprint = max(length(dFdx(uv)), length(dFdy(uv))) * scene.shading_footprint.z;
  float level;
  return material_texture_trilinear(image, uv, footprint, extension, level);
}
