// Environment maps (DESIGN §2 "Environment map orientation"): the lat-long lookup and the
// importance sampling of a piecewise-constant 2D distribution over texels, shared by C++ (the
// tests, render/gpu_envmap.cpp builds the data) and GLSL (shaders/light/light.glsl). The CPU
// reference has its own, independent code (reference/environment.cpp).
//
// Orientation: a world direction d_w reads the map at d = R d_w, R = R_y(-rotate_y_deg) M (M the
// minimal rotation taking the light's `up` to +Y); the host stores R's rows in GpuEnvMap. A local
// d = (x, y, z) reads u = atan2(x, -z) / (2 pi) wrapped into [0, 1), v = acos(y) / pi; texel
// column floor(u W), row floor(v H) (row 0 at the top, v = 0). Inversely, for (u, v):
// theta = pi v, phi = 2 pi u, d = (sin theta sin phi, cos theta, -sin theta cos phi).
//
// Sampling (pbrt's Distribution2D): texel (r, c) is drawn with probability
// P(r, c) = f(r, c) / sum f, f = luminance(texel) * sin(theta of row r's centre), as a marginal
// over rows and a conditional per row (CDFs in the data, the last entry exactly 1); the position
// inside the texel is uniform in (u, v). The density over (u, v) is P W H, and
// d omega = sin theta d theta d phi = 2 pi^2 sin theta du dv, so the pdf per solid angle is
//   pdf(d) = P(r, c) W H / (2 pi^2 sin theta).
// P comes from the CDFs' steps, so the pdf is that of the sampler exactly (a texel whose float
// step is 0 is never drawn and has pdf 0). A map with sum f = 0 (all black) is sampled
// uniformly in (u, v): its radiance is 0 everywhere, so any positive pdf will do.
//
// Data layout (float[] after the GpuEnvMap header of shared/gpu_types.h, in one buffer at
// BIND_ENV_MAP):
//   [0, 3WH)                     texel radiance RGB (times the light's `scale`), row-major
//   [3WH, 3WH + H + 1)           marginal CDF over rows
//   [3WH + H + 1, + H (W + 1))   per row r, the conditional CDF over its columns
// GLSL reads element i as ENV_DATA(i) (scene/bindings.glsl: a texel fetch; by default a global
// `envData[]`); C++ passes a pointer (ENV_DATA_*).
#ifndef PLUME_SHARED_ENVMAP_H
#define PLUME_SHARED_ENVMAP_H

#include "common.h"
#include "gpu_types.h"

#ifdef __cplusplus
#define ENV_DATA_PARAM const float *envData,
#define ENV_DATA_ARG envData,
#else
#define ENV_DATA_PARAM
#define ENV_DATA_ARG
#endif
#ifndef ENV_DATA
#define ENV_DATA(i) envData[i]
#endif

PLUME_NS_BEGIN

// Rec. 709 luminance: the sampling weight of a texel.
PLUME_FN float env_luminance(vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

PLUME_FN uint env_marginal_offset(GpuEnvMap m) { return 3u * m.width * m.height; }
PLUME_FN uint env_conditional_offset(GpuEnvMap m, uint row) {
  return 3u * m.width * m.height + m.height + 1u + row * (m.width + 1u);
}
// Floats of data after the header.
PLUME_FN uint env_data_size(uint width, uint height) { return 3u * width * height + height + 1u + height * (width + 1u); }

PLUME_FN vec3 env_to_local(GpuEnvMap m, vec3 w) {
  return vec3(dot(vec3(m.toLocal0), w), dot(vec3(m.toLocal1), w), dot(vec3(m.toLocal2), w));
}
PLUME_FN vec3 env_to_world(GpuEnvMap m, vec3 d) {
  return d.x * vec3(m.toLocal0) + d.y * vec3(m.toLocal1) + d.z * vec3(m.toLocal2);
}

// (u, v) of a unit local direction.
PLUME_FN vec2 env_local_uv(vec3 d) {
  float u = atan(d.x, -d.z) * (0.5f * PLUME_INV_PI);
  if (u < 0.0f) u += 1.0f;
  if (u >= 1.0f) u = 0.0f;  // -0 + 1 rounds to 1
  // acos(y) as atan2(|xz|, y): on lavapipe acos is off by up to ~6e-5 rad (0.005 of a texel
  // of a 512 x 256 map), atan2 by far less.
  float v = atan(sqrt(d.x * d.x + d.z * d.z), d.y) * PLUME_INV_PI;
  return vec2(u, v);
}

PLUME_FN vec3 env_uv_local(vec2 uv) {
  float theta = PLUME_PI * uv.y;
  float phi = 2.0f * PLUME_PI * uv.x;
  float s = sin(theta);
  return vec3(s * sin(phi), cos(theta), -s * cos(phi));
}

// The texel (column, row) that contains (u, v).
PLUME_FN uvec2 env_texel(GpuEnvMap m, vec2 uv) {
  uint c = min(uint(uv.x * float(m.width)), m.width - 1u);
  uint r = min(uint(uv.y * float(m.height)), m.height - 1u);
  return uvec2(c, r);
}

// Radiance arriving from world direction w (unit): the texel that contains its (u, v).
PLUME_FN vec3 env_radiance(ENV_DATA_PARAM GpuEnvMap m, vec3 w) {
  uvec2 t = env_texel(m, env_local_uv(env_to_local(m, w)));
  uint i = 3u * (t.y * m.width + t.x);
  return vec3(ENV_DATA(i), ENV_DATA(i + 1u), ENV_DATA(i + 2u));
}

// The interval i in [0, n) of the CDF cdf[offset .. offset + n] with cdf[i] <= u < cdf[i + 1]
// (u in [0, 1), cdf[0] = 0, cdf[n] = 1): never one of width 0.
PLUME_FN uint env_find_interval(ENV_DATA_PARAM uint offset, uint n, float u) {
  uint lo = 0u;
  uint hi = n;
  while (lo + 1u < hi) {
    uint mid = (lo + hi) / 2u;
    if (ENV_DATA(offset + mid) <= u) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return lo;
}

// The probability P(r, c) of drawing texel (c, r) = t, from the CDFs' steps.
PLUME_FN float env_texel_probability(ENV_DATA_PARAM GpuEnvMap m, uvec2 t) {
  uint mo = env_marginal_offset(m) + t.y;
  uint co = env_conditional_offset(m, t.y) + t.x;
  return (ENV_DATA(mo + 1u) - ENV_DATA(mo)) * (ENV_DATA(co + 1u) - ENV_DATA(co));
}

// pdf per solid angle of drawing world direction w (unit); 0 at the poles (sin theta = 0).
PLUME_FN float env_pdf(ENV_DATA_PARAM GpuEnvMap m, vec3 w) {
  vec3 d = env_to_local(m, w);
  float sinTheta = sqrt(max(0.0f, 1.0f - d.y * d.y));
  if (!(sinTheta > 0.0f)) return 0.0f;
  float p = env_texel_probability(ENV_DATA_ARG m, env_texel(m, env_local_uv(d)));
  return p * float(m.width) * float(m.height) / (2.0f * PLUME_PI * PLUME_PI * sinTheta);
}

// A world direction drawn from the map's distribution (u in [0, 1)²); its pdf is env_pdf.
PLUME_FN vec3 env_sample(ENV_DATA_PARAM GpuEnvMap m, vec2 u) {
  float u0 = min(u.x, 0.99999994f);
  float u1 = min(u.y, 0.99999994f);
  uint mo = env_marginal_offset(m);
  uint r = env_find_interval(ENV_DATA_ARG mo, m.height, u0);
  float c0 = ENV_DATA(mo + r);
  float dv = (u0 - c0) / (ENV_DATA(mo + r + 1u) - c0);
  uint co = env_conditional_offset(m, r);
  uint c = env_find_interval(ENV_DATA_ARG co, m.width, u1);
  float k0 = ENV_DATA(co + c);
  float du = (u1 - k0) / (ENV_DATA(co + c + 1u) - k0);
  // (Rounding may put (c + du) / W on the next texel's edge for du within ~1e-7 of 1: a set of
  // measure ~1e-7 whose pdf is then the neighbour's.)
  float fu = (float(c) + clamp(du, 0.0f, 1.0f)) / float(m.width);
  float fv = (float(r) + clamp(dv, 0.0f, 1.0f)) / float(m.height);
  return env_to_world(m, env_uv_local(vec2(fu, fv)));
}

PLUME_NS_END

#endif
