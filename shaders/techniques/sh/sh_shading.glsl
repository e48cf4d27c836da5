/* kautz2002: the BRDF times the cosine as SH coefficients per local view (a table), the lighting as SH, the
 * shading integral as their dot product (eq. 1).  Per pixel, in the paper's steps: the view into the local
 * frame, the table lookup by it, then (ours, on the GPU) one rotation (sh_rotate) of the looked-up vector
 * into the world frame, where the environment's coefficients live (the same dot product as rotating the
 * lighting into the local frame, one vector instead of three colours).  Lights are caps (point and spot
 * lights and area lights' patches, by sphere_light_cap) and SGs (suns), zonal about their direction: Phi g_l Y_lm(axis).  Diffuse:
 * the clamped cosine's bands A_l (Funk-Hecke), the lights' by the addition theorem; a light wholly below
 * the horizon adds nothing (its expansion would add only ringing).  Every band of the lighting is scaled by
 * the window's SH_WINDOW[l].  Mirrored by techniques/sh/sh_shading.py.
 *
 * HAS_TRANSFER (a transfer bake, techniques/sh/spherical_harmonics.py): the environment through the vertex's
 * transfer, T L and t . L weighed from sh_transfer_radiance (row k: term k of the transfer times the
 * windowed lighting; columns 0 .. SH_COUNT - 1: T_k L, SH_COUNT: t_k . L) by transfer_rows; each light's
 * diffuse term t . L_light with t rebuilt from transfer_basis, its glossy term times the same visible
 * fraction of the light.  VERTEX_TRANSFER (where the varyings hold them): the sums over the terms made per
 * vertex once per lighting (spherical_harmonics.vertex_transfer_values), transfer_rows the pixel's
 * interpolated T L (SH_COUNT RGB), t . L (RGB) and (HAS_LIGHTS) t, packed 4 floats a vec4: the per-pixel
 * loop over up to 47 terms (26 fetches each) was most of the frame (docs/PERFORMANCE.md).
 *
 * Needs sh_library.glsl and its generated constants, surface_common.glsl, (HAS_LIGHTS) lights.glsl, the
 * samplers sh_table (the BRDF product, ceil(SH_COUNT / 4) layers) and sh_environment (SH_COUNT x 1, rgb),
 * and the push constant sh_axis of the table's parameter axis (harmonics.brdf_table.BrdfTable.parameter_coordinate):
 * x 1 / (high - low) (a log axis: 1 / log(high / low)), y low, z 1 for a log axis, w the node count.
 *
 * SH_FITTED (with SH_ISOTROPIC: a stored lobe fit, harmonics/fitted_table.py): sh_table holds each lobe's
 * coefficients with m >= 0 per texel and view node (texel (x, y)'s views in columns x V .. x V + V - 1 of row
 * y, lobe k in layers k ceil(SH_STORED / 4) ..), read with texelFetch at the texel fitted_select_texel chose
 * (common/fitted_texels.glsl) and interpolated between view nodes here; each lobe's vector is rotated, then
 * weighed by its colour and the view's S(o) / (pi o.z): the product is RGB (SH_VALUE vec3). */

#ifdef SH_FITTED
#define SH_VALUE vec3
#else
#define SH_VALUE float
#endif

#ifndef SH_FITTED
float sh_parameter_coordinate(float value)
{
  float t = sh_axis.z > 0.5 ? log(max(value, sh_axis.y) / sh_axis.y) : value - sh_axis.y;
  return (clamp(t * sh_axis.x, 0.0, 1.0) * (sh_axis.w - 1.0) + 0.5) / sh_axis.w;
}

/* The table's coefficients at local view o (and parameter coordinate p, isotropic layout). */
void sh_table_lookup(vec3 o, float p, out float c[SH_COUNT])
{
#ifdef SH_ISOTROPIC
  /* theta_v by atan (llvmpipe's acos is off by up to 1.6e-4 rad, its atan by 3e-6); below the horizon pi / 2,
   * also straight below, where atan(0, 0) would be undefined */
  vec2 uv = vec2(atan(max(length(o.xy), 1.0e-30), max(o.z, 0.0)) * (2.0 / 3.14159265358979), p);
#else
  vec3 d = safe_normalize(o);
  vec2 xy = d.z >= 0.0 ? d.xy : d.xy / max(length(d.xy), 1.0e-30);
  vec2 uv = 0.5 * (xy / (1.0 + max(d.z, 0.0)) + 1.0);
#endif
  for (int k = 0; k < (SH_COUNT + 3) / 4; k++) {
    vec4 value = texture(sh_table, vec3(uv, float(k)));
    for (int j = 0; j < 4; j++) {
      if (4 * k + j < SH_COUNT) {
        c[4 * k + j] = value[j];
      }
    }
  }
}

#endif

#ifdef SH_FITTED
/* Lobe k's coefficients at view angle theta from the fit's table: linear between the two view nodes about it
 * (clamped to the end nodes), m < 0 zero (harmonics.fitted_table.lookup). */
void sh_fitted_lookup(float theta, int lobe, out float c[SH_COUNT])
{
  int views = textureSize(sh_table, 0).x / textureSize(fitted_layers, 0).x;
  float x = clamp(theta * (2.0 / 3.14159265358979) * float(views) - 0.5, 0.0, float(views - 1));
  int low = min(int(x), views - 2);
  float t = x - float(low);
  int column = fitted_texel.x * views + low;
  for (int i = 0; i < SH_COUNT; i++) {
    c[i] = 0.0;
  }
  const int layers = (SH_STORED + 3) / 4;
  for (int k = 0; k < layers; k++) {
    vec4 below = texelFetch(sh_table, ivec3(column, fitted_texel.y, lobe * layers + k), 0);
    vec4 above = texelFetch(sh_table, ivec3(column + 1, fitted_texel.y, lobe * layers + k), 0);
    vec4 value = below + (above - below) * t;
    for (int j = 0; j < 4; j++) {
      if (4 * k + j < SH_STORED) {
        c[SH_STORED_INDEX[4 * k + j]] = value[j];
      }
    }
  }
}
#endif

/* The BRDF product at local view o in world coordinates: the table's vector rotated by frame (SH_FITTED: each
 * lobe's, weighed by its colour and S(o) / (pi o.z)). */
void sh_product(vec3 o, float parameter, mat3 frame, out SH_VALUE c[SH_COUNT])
{
#ifdef SH_FITTED
  float theta = atan(max(length(o.xy), 1.0e-30), max(o.z, 0.0));
  float view_factor = fitted_shadowing_at(theta) / (3.14159265358979 * max(o.z, SH_COSINE_EPSILON));
  for (int i = 0; i < SH_COUNT; i++) {
    c[i] = vec3(0.0);
  }
  for (int k = 0; k < FITTED_LOBES; k++) {
    float lobe[SH_COUNT];
    sh_fitted_lookup(theta, k, lobe);
    sh_rotate(lobe, frame);
    vec3 colour = fitted_layer(2 + 2 * k).rgb * view_factor;
    for (int i = 0; i < SH_COUNT; i++) {
      c[i] += colour * lobe[i];
    }
  }
#else
  sh_table_lookup(o, sh_parameter_coordinate(parameter), c);
  sh_rotate(c, frame);                          /* the product in world coordinates */
#endif
}

#ifdef VERTEX_TRANSFER
/* Value j of the pixel's transfer summed at the vertices (transfer_rows, packed 4 a vec4). */
float sh_vertex_transfer_value(int j)
{
  return transfer_rows[j / 4][j % 4];
}

vec3 sh_vertex_transfer_rgb(int j)
{
  return vec3(sh_vertex_transfer_value(j), sh_vertex_transfer_value(j + 1), sh_vertex_transfer_value(j + 2));
}
#endif

void shade_sh(vec3 position, vec3 normal, vec3 tangent, vec3 diffuse_color, vec3 specular_color, float parameter,
              out vec3 diffuse, out vec3 specular)
{
  vec3 n, t, b;
  shading_frame(normal, tangent, n, t, b);
  vec3 view = scene.camera.w > 0.5 ? safe_normalize(scene.camera.xyz - position) : -safe_normalize(scene.camera.xyz);
#ifdef SH_ISOTROPIC
  /* turn the frame about n until the view lies in its x-z plane (the table's phi_v = 0) */
  vec3 along = view - n * dot(n, view);
  if (dot(along, along) > 1.0e-12) {
    t = normalize(along);
    b = cross(n, t);
  }
#endif
  mat3 frame = mat3(t, b, n);                   /* local -> world */
  vec3 o = view * frame;                        /* world -> local: the rows */
  SH_VALUE c[SH_COUNT];
  sh_product(o, parameter, frame, c);
  float y[SH_COUNT];
  sh_basis(n, y);
  vec3 radiance = vec3(0.0);
  vec3 irradiance = vec3(0.0);
#if defined(HAS_TRANSFER) && defined(VERTEX_TRANSFER)
  /* the terms summed at the vertices, interpolated (by linearity the same sum of the interpolated weights) */
  for (int i = 0; i < SH_COUNT; i++) {
    radiance += c[i] * sh_vertex_transfer_rgb(3 * i);
  }
  irradiance = sh_vertex_transfer_rgb(3 * SH_COUNT);
#ifdef HAS_LIGHTS
  float diffuse_transfer[SH_COUNT];             /* t(p) */
  for (int i = 0; i < SH_COUNT; i++) {
    diffuse_transfer[i] = sh_vertex_transfer_value(3 * SH_COUNT + 3 + i);
  }
#endif
#elif defined(HAS_TRANSFER)
  for (int k = 0; k < 4 * TRANSFER_LAYERS; k++) {
    float weight = transfer_rows[k / 4][k % 4];
    for (int i = 0; i < SH_COUNT; i++) {
      radiance += (weight * c[i]) * texelFetch(sh_transfer_radiance, ivec2(i, k), 0).rgb;
    }
    irradiance += weight * texelFetch(sh_transfer_radiance, ivec2(SH_COUNT, k), 0).rgb;
  }
#ifdef HAS_LIGHTS
  float diffuse_transfer[SH_COUNT];             /* t(p): the mean and the terms, weighed */
  for (int i = 0; i < SH_COUNT; i++) {
    diffuse_transfer[i] = 0.0;
  }
  for (int layer = 0; layer < TRANSFER_LAYERS; layer++) {
    for (int i = 0; i < SH_COUNT; i++) {
      diffuse_transfer[i] += dot(transfer_rows[layer], texelFetch(transfer_basis, ivec3(i, 0, layer), 0));
    }
  }
#endif
#else
  for (int l = 0; l < SH_ORDER; l++) {
    for (int i = l * l; i < (l + 1) * (l + 1); i++) {
      vec3 light = SH_WINDOW[l] * texelFetch(sh_environment, ivec2(i, 0), 0).rgb;
      radiance += c[i] * light;
      irradiance += (SH_COSINE[l] * y[i]) * light;
    }
  }
#endif
#ifdef HAS_LIGHTS
  for (int l = 0; l < scene.counts.x + scene.counts.y; l++) {
    vec3 axis;
    vec3 flux;
    float g[SH_ORDER];
    float sin2;                                  /* of the light's angular radius */
    if (l < scene.counts.x) {
      float effective2;
      sin2 = light_cap(position, scene.point_position_radius[l].xyz, scene.point_position_radius[l].w,
                       scene.point_intensity[l].a > 0.5, effective2, axis);
      float cos_half = sqrt(max(1.0 - sin2, 0.0));
      sh_cap_factors(sin2 / (1.0 + cos_half), g);
      /* radiance I / (pi r^2) over the cap's solid angle 2 pi (1 - cos): 2 I / (effective2 (1 + cos)) */
      flux = scene.point_intensity[l].rgb * (2.0 / (effective2 * (1.0 + cos_half))) * scene_light_emission(l, axis);
    }
    else {
      int s = l - scene.counts.x;
      axis = scene.sun_axis_sharpness[s].xyz;
      float lambda = scene.sun_axis_sharpness[s].w;
      sh_sg_factors(lambda, g);
      sin2 = min(LIGHT_LN10 / max(lambda, 1.0e-6), 1.0);     /* the cap the SG stands for (lights.glsl) */
      /* the SG's integral over the sphere */
      flux = scene.sun_amplitude[s].rgb * sg_sphere_integral(lambda, 1.0);
    }
    float ya[SH_COUNT];
    sh_basis(axis, ya);
    SH_VALUE glossy = SH_VALUE(0.0);
    float zonal[SH_ORDER];
#ifdef HAS_TRANSFER
    float shadowed = 0.0;
#endif
    for (int k = 0; k < SH_ORDER; k++) {
      float w = SH_WINDOW[k] * g[k];
      zonal[k] = w * SH_COSINE[k];
      for (int i = k * k; i < (k + 1) * (k + 1); i++) {
        glossy += w * c[i] * ya[i];
#ifdef HAS_TRANSFER
        shadowed += w * diffuse_transfer[i] * ya[i];
#endif
      }
    }
    float unshadowed = sh_zonal_sum(zonal, dot(n, axis));
    /* a light wholly below the horizon lights nothing: its expansion would only add the product's ringing */
    float above = dot(n, axis) > -sqrt(sin2) ? 1.0 : 0.0;
#ifdef HAS_TRANSFER
    /* the visible fraction of the light's clamped-cosine integral shadows its glossy term too */
    radiance += flux * (above * glossy * (unshadowed > 1.0e-12 ? clamp(shadowed / unshadowed, 0.0, 1.0) : 0.0));
    irradiance += flux * (above * shadowed);
#else
    radiance += flux * (above * glossy);
    irradiance += flux * (above * unshadowed);
#endif
  }
#endif
  diffuse = diffuse_color * (1.0 / 3.14159265358979) * max(irradiance, vec3(0.0));
  specular = specular_color * max(radiance, vec3(0.0));
}
