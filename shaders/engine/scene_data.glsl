/* Uniform buffer layouts (std140, vec4 slots only).  Filled by
 * sg_prt_addon/engine/renderer.py (scene_block, material_block); sizes come from the SGPRT_MAX_* defines
 * (techniques/shader_sources.py LIMITS). */

struct SceneData {
  /* xyz: camera position (perspective) or camera forward (orthographic); w: 1 perspective, 0 ortho */
  vec4 camera;
  /* rgb: the world colour; with an environment texture its mean radiance, w = 1 when the
   * lookup blends to it below the broadest prefiltered level */
  vec4 world_colour;
  /* x point/spot lights, y suns, z environment SG lobes, w prefiltered layers */
  ivec4 counts;
  /* x log2 of the first layer's sharpness, y levels per octave, z last layer index */
  vec4 prefilter_info;
  /* per layer: x texcoord scale, y texcoord offset */
  vec4 prefilter_scale_offset[SGPRT_MAX_LAYERS];
  /* xyz position, w radius */
  vec4 point_position_radius[SGPRT_MAX_POINT_LIGHTS];
  /* rgb radiant intensity (W/sr); a: 1 for Blender's Soft Falloff (the light a disk facing the point: lights.glsl
   * light_cap), 0 a sphere */
  vec4 point_intensity[SGPRT_MAX_POINT_LIGHTS];
  /* xyz spot axis, w spot size (full cone angle; negative: a point light) */
  vec4 spot_direction_size[SGPRT_MAX_POINT_LIGHTS];
  /* x spot blend; y 1 for an area light's patch (one-sided along the spot axis), z tan of its spread's half
   * angle, w the spread's normalization (0: none): lights.glsl light_emission_factor */
  vec4 spot_blend[SGPRT_MAX_POINT_LIGHTS];
  /* suns as ready SGs: xyz axis, w sharpness; rgb amplitude */
  vec4 sun_axis_sharpness[SGPRT_MAX_SUNS];
  vec4 sun_amplitude[SGPRT_MAX_SUNS];
  /* diffuse environment SG mixture (env_fit) */
  vec4 env_axis_sharpness[SGPRT_MAX_ENV_LOBES];
  vec4 env_amplitude[SGPRT_MAX_ENV_LOBES];
  /* lobe e's clamped_cosine_sharpness_terms (spherical.clamped_cosine.sharpness_terms): [2e], [2e + 1] */
  vec4 env_cosine_terms[2 * SGPRT_MAX_ENV_LOBES];
  /* world -> clip of the surface draws (push constants stay within 128 bytes: model matrix + G-buffer ids) */
  mat4 view_projection;
  /* x: the side, in pixels, of the square each pixel's shading averages its specular over (engine/
   * anti_aliasing.py specular_footprint): 1 one frame, 1/m each of m x m jittered frames, 0 the centre alone;
   * y: the most samples a side of that square (anti_aliasing.footprint_grid_limit); z: the side, in pixels, of
   * the square each pixel's material textures are read over (anti_aliasing.texture_footprint); w: the frame's
   * offset of the dithered coverage's thresholds (common/surface_io.glsl surface_coverage) */
  vec4 shading_footprint;
  /* the lights' shadow maps (lighting/shadow_maps.py ShadowPlan): x tile side (texels, 0: none), y tiles a row,
   * z a face's share of its tile, w lights with a map */
  vec4 shadow_atlas;
  /* the light of each shadow slot, four a vec4 (point lights first, then suns from counts.x) */
  vec4 shadow_slot_light[SGPRT_MAX_SHADOW_MAPS / 4];
  /* x slot (-1: no map), y first of its six tiles, z near, w far */
  vec4 point_shadow[SGPRT_MAX_POINT_LIGHTS];
  /* x slot (-1: no map), y tile, z a texel's world size, w the map's depth range; rows: ndc x, ndc y and
   * depth01 of (p, 1); x of radius: the tangent of the sun's angular radius */
  vec4 sun_shadow[SGPRT_MAX_SUNS];
  vec4 sun_shadow_rows[3 * SGPRT_MAX_SUNS];
  vec4 sun_shadow_radius[SGPRT_MAX_SUNS];
};

struct MaterialData {
  /* rgb kd; w the F0 of the dielectric layer over the diffuse (negative: none; common/surface_layering.glsl) */
  vec4 diffuse_color;
  vec4 specular_color;
  /* roughness, ior, exponent, alpha_x */
  vec4 parameters0;
  /* alpha_y, nu, nv, normal_strength */
  vec4 parameters1;
  /* xyz object-space tangent axis, w tangent rotation (radians) */
  vec4 tangent_axis_rotation;
  /* x tangent source: 0 UV map, 1 object axis; y the material's G-buffer id; z the layer's GGX roughness;
   * w the surface's coverage (alpha: common/surface_io.glsl surface_coverage) */
  vec4 options;
  /* rgb emitted radiance (Combined only); w the holdout's share of the drawn surface (Combined's alpha 1 - w) */
  vec4 emission;
  /* the texture coordinates from the UV map (a node tree's Mapping): u' = dot(xyz, (u, v, 1)), v' likewise */
  vec4 uv_transform_u;
  vec4 uv_transform_v;
};
