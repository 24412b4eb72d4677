// The bridge between ReSTIR's algorithm (shared/reservoir.h, shared/restir_types.h) and our
// resources: domains (a pixel of a frame, with that frame's volume), lights, the path
// contribution f_D(y) — approximate (the target p̂) or unbiased (final shading) — and reservoir
// and path storage. Candidates and the reuse step build on it (candidates.glsl, reuse.glsl).
// Requires restir/bindings.glsl, volume/volume.glsl (unbiased tracking on the current volume)
// and restir/coarse.glsl.
#ifndef PLUME_RESTIR_BRIDGE_GLSL
#define PLUME_RESTIR_BRIDGE_GLSL

#include "../shared/phase.h"
#include "../shared/rng.h"
#include "../shared/sampling.h"

// A domain of the integral: one pixel of one frame (its camera and that frame's volume). The
// pixel's box filter is part of the path: a path starts with its position (u, v) in [0, 1]² inside
// the pixel, and the shift copies it, so a still camera's history is the same domain (identity
// shift, equal targets) and neighbours use the same sub-pixel offset.
struct RsDomain {
  vec3 origin;
  vec3 corner;  // un-normalised direction through the pixel's corner (u, v) = (0, 0)
  vec3 du;      // its change per unit of u (one pixel to the right)
  vec3 dv;      // and per unit of v (one pixel down)
  uint v;       // 0: current volume, 1: previous
};

RsDomain rs_camera_domain(uvec2 pixel, vec4 pos, vec4 fwd, vec4 right, vec4 up, uint v) {
  RsDomain D;
  D.origin = pos.xyz;
  D.corner = cam_direction(vec2(pixel), frame.image.xy, pos, fwd, right, up);
  D.du = (2.0f / float(frame.image.x)) * pos.w * fwd.w * right.xyz;
  D.dv = (-2.0f / float(frame.image.y)) * pos.w * up.xyz;
  D.v = v;
  return D;
}

// The camera ray through the point (u, v) of the domain's pixel.
vec3 rs_domain_dir(RsDomain D, vec2 uv) { return normalize(D.corner + uv.x * D.du + uv.y * D.dv); }

RsDomain rs_current_domain(uvec2 pixel) {
  return rs_camera_domain(pixel, frame.camPosition, frame.camForward, frame.camRight, frame.camUp, 0u);
}

RsDomain rs_previous_domain(uvec2 pixel) {
  return rs_camera_domain(pixel, rsp.prevCamPosition, rsp.prevCamForward, rsp.prevCamRight, rsp.prevCamUp, 1u);
}

// A path's sub-pixel position, stored in RsPathHead.info.w as two 16-bit fixed-point numbers;
// candidates quantise their draw first, so every domain sees exactly the stored value.
uint rs_pack_uv(vec2 uv) { return packUnorm2x16(uv); }
vec2 rs_unpack_uv(uint packed) { return unpackUnorm2x16(packed); }

float rs_luminance(vec3 c) { return (c.x + c.y + c.z) * (1.0f / 3.0f); }

// --- Lights ----------------------------------------------------------------------------------
// Direction (unit, towards the light), distance and emitted term of a light sample at x:
// sun delta: irradiance; sun disk and environment: radiance (per unit solid angle of w);
// point: intensity / r^2. The sample's two floats hold w for the disk and the environment.
bool rs_light_geometry(GpuLight l, vec3 x, vec2 ls, out vec3 w, out float dist, out vec3 Le) {
  uint type = uint(l.params.x);
  dist = DDA_INF;
  Le = l.emission.rgb;
  w = vec3(0.0f, 0.0f, 1.0f);
  // Light types missing from the scene are compiled out (PLUME_HAS_SUN, _POINT, _ENV).
#ifdef PLUME_HAS_SUN
  if (type == LIGHT_SUN) {
    // A disk: the stored direction must lie in the cone (up to its float encoding's rounding).
    w = l.params.y <= 0.0f ? l.dirOrPos.xyz : rs_decode_dir(ls);
    return l.params.y <= 0.0f || smp_versine(w, l.dirOrPos.xyz) <= l.params.y * 1.001f;
  }
#endif
#ifdef PLUME_HAS_POINT
  if (type == LIGHT_POINT) {
    vec3 toL = l.dirOrPos.xyz - x;
    dist = length(toL);
    if (!(dist > 0.0f)) return false;
    w = toL / dist;
    Le = l.emission.rgb / (dist * dist);
    return true;
  }
#endif
#ifdef PLUME_HAS_ENV
  w = rs_decode_dir(ls);  // environment
  return true;
#else
  return false;
#endif
}

// Draws a light sample at x for a path arriving along wIn: the light chosen with the
// probabilities the host stored (params.z, running sums in params.w; render/restir.cpp); the disk
// uniformly in its cone; the environment by phase sampling. Returns the sample's pdf (in the
// light's measure, times the light's choice probability) or 0.
float rs_sample_light(vec3 wIn, float g, vec3 u, out uint light, out vec2 ls) {
  uint n = rsp.frames.w;
  light = 0u;
  while (light + 1u < n && u.x >= lights[light].params.w) ++light;
  GpuLight l = lights[light];
  uint type = uint(l.params.x);
  float pdf = l.params.z;
  ls = vec2(0.0f);
#ifdef PLUME_HAS_SUN
  if (type == LIGHT_SUN) {
    if (l.params.y <= 0.0f) return pdf;
    ls = rs_encode_dir(smp_uniform_cone(l.dirOrPos.xyz, l.params.y, u.yz));
    vec3 w = rs_decode_dir(ls);
    return smp_versine(w, l.dirOrPos.xyz) <= l.params.y * 1.001f ? pdf * smp_uniform_cone_pdf(l.params.y) : 0.0f;
  }
#endif
#ifdef PLUME_HAS_POINT
  if (type == LIGHT_POINT) return pdf;
#endif
#ifdef PLUME_HAS_ENV
  ls = rs_encode_dir(ph_hg_sample(wIn, g, u.yz));
  return pdf * ph_hg(dot(rs_decode_dir(ls), wIn), g);
#else
  return 0.0f;
#endif
}

// Transmittance: the coarse deterministic one (target) or residual ratio tracking on the fine grid
// of the current volume against the same coarse field (unbiased; final shading only, v = 0).
float rs_transmittance(uint v, vec3 x, vec3 w, float dist, bool unbiased, inout RngState rng) {
  return unbiased ? rs_residual_tr(x, w, dist, rng) : rs_coarse_tr(v, x, w, dist);
}

// The light term at the path's last vertex x (path arriving along wIn): Le * phase * T.
vec3 rs_light_term(uint v, uint light, vec2 ls, vec3 x, vec3 wIn, bool unbiased, inout RngState rng) {
  vec3 w;
  float dist;
  vec3 Le;
  if (!rs_light_geometry(lights[light], x, ls, w, dist, Le)) return vec3(0.0f);
  return Le * ph_hg(dot(w, wIn), frame.albedo.w) * rs_transmittance(v, x, w, dist, unbiased, rng);
}

// --- Path storage ----------------------------------------------------------------------------
uint rs_slot(uint set, uint pixelIndex) { return set * rsp.frames.y + pixelIndex; }
uint rs_bounce_base(uint set, uint pixelIndex) { return rs_slot(set, pixelIndex) * rsp.config.w; }

RsReservoir rs_load(uint set, uint pixelIndex) {
  bool dropped;
  RsReservoir r = rs_unpack(rsReservoirs[rs_slot(set, pixelIndex)], dropped);
  if (dropped) atomicAdd(rsCounters[0], 1u);
  return r;
}

void rs_store(uint set, uint pixelIndex, RsReservoir r) { rsReservoirs[rs_slot(set, pixelIndex)] = rs_pack(r); }

void rs_copy_path(uint srcSet, uint srcPixel, uint dstSet, uint dstPixel) {
  RsPathHead h = rsPaths[rs_slot(srcSet, srcPixel)];
  rsPaths[rs_slot(dstSet, dstPixel)] = h;
  uint a = rs_bounce_base(srcSet, srcPixel);
  uint b = rs_bounce_base(dstSet, dstPixel);
  for (uint i = 1u; i < h.info.x; ++i) rsBounces[b + i - 1u] = rsBounces[a + i - 1u];
}

// --- The path contribution f_D(y) ------------------------------------------------------------
// y is the path stored at (set, pixel); D any domain. Vertices x_1 = o + t1 d(u, v), x_i = x_{i-1} +
// t_i w_i; f = prod_i [T(x_{i-1}, x_i) sigma_s(x_i)] * prod_{i>=2} phase(w_{i-1}, w_i) * light
// term, RGB. A vertex with zero density (or outside the volume) makes f = 0: the shift fails.
vec3 rs_path_contribution(RsDomain D, uint set, uint pixelIndex, bool unbiased, inout RngState rng) {
  RsPathHead h = rsPaths[rs_slot(set, pixelIndex)];
  uint n = h.info.x;
  if (n == 0u) return vec3(0.0f);
  uint base = rs_bounce_base(set, pixelIndex);
  vec3 x = D.origin;
  vec3 w = rs_domain_dir(D, rs_unpack_uv(h.info.w));
  float t = h.geo.x;
  vec3 f = vec3(1.0f);
  for (uint i = 1u; i <= n; ++i) {
    if (i >= 2u) {
      vec4 b = rsBounces[base + i - 2u];
      f *= ph_hg(dot(w, b.xyz), frame.albedo.w);
      w = b.xyz;
      t = b.w;
    }
    float tr = rs_transmittance(D.v, x, w, t, unbiased, rng);
    x += t * w;
    float sigma = rsv_sigma_t(D.v, x);
    if (!(sigma > 0.0f)) return vec3(0.0f);
    f *= tr * sigma * frame.albedo.rgb;
  }
  return f * rs_light_term(D.v, h.info.y, h.geo.yz, x, w, unbiased, rng);
}

// The target function p̂_D(y): deterministic (no random numbers are drawn on this path).
float rs_target(RsDomain D, uint set, uint pixelIndex) {
  RngState unused = RngState(uvec4(0u), 0u);  // never drawn from: no hash to pay for
  return rs_luminance(rs_path_contribution(D, set, pixelIndex, false, unused));
}

#endif
