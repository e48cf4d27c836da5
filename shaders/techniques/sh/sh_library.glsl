/* Real spherical harmonics of order SH_ORDER (SH_COUNT = SH_ORDER^2 coefficients, (l, m) at l^2 + l + m,
 * Condon-Shortley phase: sg_prt_addon/harmonics, whose numpy this mirrors).  Needs the generated constants
 * (techniques/sh/sh_glsl.py): SH_NORMALIZATION (K_lm, times sqrt(2) for m > 0, at l (l + 1) / 2 + m) and
 * sh_rotate_x90 / sh_rotate_x90_inverse. */

/* Y_i(d) of a unit direction: P_l^m / sin^m by the recurrences in l, times Re / Im of (x + i y)^m. */
void sh_basis(vec3 d, out float y[SH_COUNT])
{
  float cosine_part = 1.0;
  float sine_part = 0.0;
  float diagonal = 1.0;
  for (int m = 0; m < SH_ORDER; m++) {
    if (m > 0) {
      float next = cosine_part * d.x - sine_part * d.y;
      sine_part = cosine_part * d.y + sine_part * d.x;
      cosine_part = next;
      diagonal *= -float(2 * m - 1);
    }
    float before = 0.0;
    float current = diagonal;
    for (int l = m; l < SH_ORDER; l++) {
      if (l == m + 1) {
        before = current;
        current = d.z * float(2 * m + 1) * diagonal;
      }
      else if (l > m + 1) {
        float next = (float(2 * l - 1) * d.z * current - float(l + m - 1) * before) / float(l - m);
        before = current;
        current = next;
      }
      float k = SH_NORMALIZATION[l * (l + 1) / 2 + m] * current;
      if (m == 0) {
        y[l * l + l] = k;
      }
      else {
        y[l * l + l + m] = k * cosine_part;
        y[l * l + l - m] = k * sine_part;
      }
    }
  }
}

/* Rotation about z by angle: the pair (m, -m) of every band turns by m angle. */
void sh_rotate_z(inout float c[SH_COUNT], float angle)
{
  float cosine = cos(angle);
  float sine = sin(angle);
  float cm = 1.0;
  float sm = 0.0;
  for (int m = 1; m < SH_ORDER; m++) {
    float next = cm * cosine - sm * sine;
    sm = sm * cosine + cm * sine;
    cm = next;
    for (int l = m; l < SH_ORDER; l++) {
      int plus = l * l + l + m;
      int minus = l * l + l - m;
      float a = c[plus];
      float b = c[minus];
      c[plus] = cm * a - sm * b;
      c[minus] = sm * a + cm * b;
    }
  }
}

/* c <- M(R) c for a rotation R (columns: the images of x, y, z), kautz2002's zyz method:
 * R = Rz(alpha) Ry(beta) Rz(gamma), Ry(beta) = Rx(-90) Rz(beta) Rx(90).  At beta = 0 or pi only
 * alpha +- gamma is defined: gamma = 0 there (harmonics.rotation.euler_zyz_many). */
void sh_rotate(inout float c[SH_COUNT], mat3 R)
{
  /* GLSL's R[column][row] */
  float sine_beta = length(vec2(R[2][0], R[2][1]));
  float beta = atan(sine_beta, R[2][2]);
  float alpha, gamma;
  if (sine_beta > 1.0e-6) {
    alpha = atan(R[2][1], R[2][0]);
    gamma = atan(R[1][2], -R[0][2]);
  }
  else {
    alpha = R[2][2] > 0.0 ? atan(R[0][1], R[0][0]) : atan(-R[0][1], -R[0][0]);
    gamma = 0.0;
  }
  sh_rotate_z(c, gamma);
  sh_rotate_x90(c);
  sh_rotate_z(c, beta);
  sh_rotate_x90_inverse(c);
  sh_rotate_z(c, alpha);
}

/* g_l (g_0 = 1) of a uniform cap with 1 - cos(half angle) = epsilon: the integral of P_l over the cap
 * over the cap's solid angle, (P_{l-1}(x) - P_{l+1}(x)) / ((2l + 1) epsilon); below epsilon 1e-3 its
 * series 1 - l (l + 1) epsilon / 4 (float32 would cancel). */
void sh_cap_factors(float epsilon, out float g[SH_ORDER])
{
  if (epsilon < 1.0e-3) {
    for (int l = 0; l < SH_ORDER; l++) {
      g[l] = 1.0 - float(l * (l + 1)) * epsilon * 0.25;
    }
    return;
  }
  float x = 1.0 - epsilon;
  float p_before = 1.0;            /* P_{l-1} */
  float p_current = x;             /* P_l */
  g[0] = 1.0;
  for (int l = 1; l < SH_ORDER; l++) {
    float p_next = (float(2 * l + 1) * x * p_current - float(l) * p_before) / float(l + 1);
    g[l] = (p_before - p_next) / (float(2 * l + 1) * epsilon);
    p_before = p_current;
    p_current = p_next;
  }
}

/* g_l of an SG of sharpness lambda: i_l(lambda) / i_0(lambda) (modified spherical Bessel functions).
 * lambda >= 10: the upward recurrence g_{l+1} = g_{l-1} - (2l + 1) g_l / lambda from g_1 = coth - 1 / lambda
 * (stable there); below: the ratios i_l / i_{l-1} by a downward recurrence from SH_ORDER + 16 (Miller's). */
void sh_sg_factors(float sharpness, out float g[SH_ORDER])
{
  float lambda = max(sharpness, 1.0e-6);
  g[0] = 1.0;
  if (lambda >= 10.0) {
    float e = exp(-2.0 * lambda);
    if (SH_ORDER > 1) {
      g[1] = (1.0 + e) / (1.0 - e) - 1.0 / lambda;
    }
    for (int l = 1; l + 1 < SH_ORDER; l++) {
      g[l + 1] = g[l - 1] - float(2 * l + 1) / lambda * g[l];
    }
    return;
  }
  float ratio[SH_ORDER];
  float r = 0.0;
  for (int l = SH_ORDER + 16; l >= 1; l--) {
    r = 1.0 / (float(2 * l + 1) / lambda + r);
    if (l < SH_ORDER) {
      ratio[l] = r;
    }
  }
  for (int l = 1; l < SH_ORDER; l++) {
    g[l] = g[l - 1] * ratio[l];
  }
}

/* sum over l of weights[l] (2l + 1) / (4 pi) P_l(t): a zonal expansion at cosine t (the addition theorem). */
float sh_zonal_sum(float weights[SH_ORDER], float t)
{
  float p_before = 1.0;
  float p_current = t;
  float total = weights[0] * (1.0 / (4.0 * 3.14159265358979));
  for (int l = 1; l < SH_ORDER; l++) {
    total += weights[l] * float(2 * l + 1) * (1.0 / (4.0 * 3.14159265358979)) * p_current;
    float p_next = (float(2 * l + 1) * t * p_current - float(l) * p_before) / float(l + 1);
    p_before = p_current;
    p_current = p_next;
  }
  return total;
}
