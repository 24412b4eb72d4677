// The bridge between ReSTIR's algorithm (shared/reservoir.h, shared/restir_types.h,
// shared/restir_mis.h) and our resources: domains (a pixel of a frame, with that frame's volume),
// light samples, the path contribution f_D(y) — approximate (the target p̂) or unbiased (final
// shading) — and reservoir and path storage. Candidates and the reuse step build on it
// (candidates.glsl, reuse.glsl). Requires restir/bindings.glsl.
#ifndef PLUME_RESTIR_BRIDGE_GLSL
#define PLUME_RESTIR_BRIDGE_GLSL

#include "../shared/rng.h"
#include "../volume/grid.glsl"
#include "../volume/walk.glsl"
#include "../light/light.glsl"
#include "../integrator/vertex.glsl"

// A domain of the integral: one pixel of one frame (its camera and that frame's volume). The
// pixel's box filter is part of the path: a path starts with its position (u, v) in [0, 1]² inside
// the pixel, and the shift copies it, so a still camera's history is the same domain (identity
// shift, equal targets) and neighbours use the same sub-pixel offset.
struct RsDomain {
  vec3 origin;
  vec3 corner;  // un-normalised direction through the pixel's corner (u, v) = (0, 0)
  vec3 du;      // its change per unit of u (one pixel to the right)
  vec3 dv;      // and per unit of v (one pixel down)
  uint v;       // VOL_CURRENT or VOL_PREVIOUS
};

RsDomain rs_camera_domain(uvec2 pixel, GpuCamera cam, uint v) {
  RsDomain D;
  D.origin = cam.position;
  D.corner = cam_direction(vec2(pixel), frame.size, cam);
  D.du = (2.0f / float(frame.size.x)) * cam.tanHalfFovY * cam.aspect * cam.right;
  D.dv = (-2.0f / float(frame.size.y)) * cam.tanHalfFovY * cam.up;
  D.v = v;
  return D;
}

// The camera ray through the point (u, v) of the domain's pixel.
vec3 rs_domain_dir(RsDomain D, vec2 uv) { return normalize(D.corner + uv.x * D.du + uv.y * D.dv); }

RsDomain rs_current_domain(uvec2 pixel) { return rs_camera_domain(pixel, frame.camera, VOL_CURRENT); }
RsDomain rs_previous_domain(uvec2 pixel) { return rs_camera_domain(pixel, rsp.prevCamera, VOL_PREVIOUS); }

// A path's sub-pixel position, stored in RsPathHead.uv as two 16-bit fixed-point numbers;
// candidates quantise their draw first, so every domain sees exactly the stored value.
uint rs_pack_uv(vec2 uv) { return packUnorm2x16(uv); }
vec2 rs_unpack_uv(uint packed) { return unpackUnorm2x16(packed); }

float rs_luminance(vec3 c) { return (c.x + c.y + c.z) * (1.0f / 3.0f); }

// --- Light samples -------------------------------------------------------------------------------
// A path ends in a light sample (light index, two floats): a direction sample is stored as
// rs_encode_dir of it, and every domain reconnects to the decoded direction (or, for a point
// light or a delta sun, to the light itself).

// Draws a light sample at a vertex for a path arriving along wIn: the light chosen with the
// probabilities the host stored (lightChoice; render/restir.cpp), then light_sample_dir. Returns
// the sample's pdf (the light's, at the stored direction, times the choice probability) or 0.
float rs_sample_light(vec3 wIn, vec3 u, out uint light, out vec2 ls) {
  uint n = rsp.lightCount;
  light = 0u;
  while (light + 1u < n && u.x >= lightChoice[light].cdf) ++light;
  GpuLight l = lights[light];
  float pdf = lightChoice[light].probability;
  ls = vec2(0.0f);
  if (!light_samples_direction(l)) return pdf;
  ls = rs_encode_dir(light_sample_dir(l, vec3(0.0f), wIn, frame.g, u.yz));
  return pdf * light_pdf(l, rs_decode_dir(ls), wIn, frame.g);
}

#ifdef PLUME_HAS_EMISSION
// The most vertices of a path a reservoir holds that ends in emission: one more than the light
// paths' min(max_bounces, K) (its last vertex only emits), at most RS_MAX_VERTICES. Longer
// emitting paths are the tail's (restir/shade.glsl); one-vertex ones final shading's.
uint rs_emission_vertices() {
  return min(min(frame.maxBounces + 1u, rsp.prefixVertices + 1u), RS_MAX_VERTICES);
}
#endif

// Transmittance: the mean field's deterministic one (target) or residual ratio tracking on the
// fine grid of the current volume against the same field (unbiased; final shading only, v = 0).
float rs_transmittance(uint v, vec3 x, vec3 w, float dist, bool unbiased, inout RngState rng) {
  return unbiased ? vol_residual_tr(x, w, dist, rng) : vol_mean_tr(v, x, w, dist);
}

// The light term at the path's last vertex x (kind `kind`, path arriving along wIn): Le * scatter * T.
vec3 rs_light_term(uint v, uint kind, uint light, vec2 ls, vec3 x, vec3 wIn, bool unbiased, inout RngState rng) {
  GpuLight l = lights[light];
  vec3 w;
  float dist;
  vec3 Le;
  if (!light_connect(l, x, rs_decode_dir(ls), w, dist, Le)) return vec3(0.0f);
  return Le * vtx_scatter(kind, w, wIn) * rs_transmittance(v, x, w, dist, unbiased, rng);
}

// --- Path storage --------------------------------------------------------------------------------
uint rs_slot(uint set, uint pixelIndex) { return set * rsp.pixelCount + pixelIndex; }
uint rs_bounce_base(uint set, uint pixelIndex) { return rs_slot(set, pixelIndex) * rsp.bounceStride; }

RsReservoir rs_load(uint set, uint pixelIndex) {
  bool dropped;
  RsReservoir r = rs_unpack(rsReservoirs[rs_slot(set, pixelIndex)], dropped);
  if (dropped) atomicAdd(rsCounters[0], 1u);
  return r;
}

void rs_store(uint set, uint pixelIndex, RsReservoir r) { rsReservoirs[rs_slot(set, pixelIndex)] = rs_pack(r); }

RsPathHead rs_load_head(uint set, uint pixelIndex) {
  uint i = 2u * rs_slot(set, pixelIndex);
  uvec4 a = rsPathWords[i];
  uvec4 b = rsPathWords[i + 1u];
  RsPathHead h;
  h.lightSample = uintBitsToFloat(a.xy);
  h.t1 = uintBitsToFloat(a.z);
  h.vertexCount = a.w;
  h.light = b.x;
  h.kinds = b.y;
  h.uv = b.z;
  h.pad0 = b.w;
  return h;
}

void rs_store_head(uint set, uint pixelIndex, RsPathHead h) {
  uint i = 2u * rs_slot(set, pixelIndex);
  rsPathWords[i] = uvec4(floatBitsToUint(h.lightSample), floatBitsToUint(h.t1), h.vertexCount);
  rsPathWords[i + 1u] = uvec4(h.light, h.kinds, h.uv, h.pad0);
}

// A pixel's state between the dispatches of one pass (RS_STATE_SLOTS vec4s past the
// accumulation): the candidates' running reservoir (restir/candidates.glsl), then final
// shading's tail (restir/shade.glsl).
uint rs_state_slot(uint pixelIndex) { return 2u * rsp.pixelCount + RS_STATE_SLOTS * pixelIndex; }

// Vertex count of the stored path (0: none), and marking a slot empty.
uint rs_path_length(uint set, uint pixelIndex) { return rsPathWords[2u * rs_slot(set, pixelIndex)].w; }
void rs_clear_path(uint set, uint pixelIndex) { rsPathWords[2u * rs_slot(set, pixelIndex)].w = 0u; }

void rs_copy_path(uint srcSet, uint srcPixel, uint dstSet, uint dstPixel) {
  uint s = 2u * rs_slot(srcSet, srcPixel);
  uint d = 2u * rs_slot(dstSet, dstPixel);
  uvec4 head = rsPathWords[s];
  rsPathWords[d] = head;
  rsPathWords[d + 1u] = rsPathWords[s + 1u];
  uint a = rs_bounce_base(srcSet, srcPixel);
  uint b = rs_bounce_base(dstSet, dstPixel);
  for (uint i = 1u; i < head.w; ++i) rsBounces[b + i - 1u] = rsBounces[a + i - 1u];
}

// --- The path contribution f_D(y) ----------------------------------------------------------------
// y is the path stored at (set, pixel); D any domain. Vertices x_1 = o + t1 d(u, v), x_i = x_{i-1} +
// t_i w_i; f = prod_i [T(x_{i-1}, x_i) sigma_s(x_i)] * prod_{i>=2} scatter(w_{i-1}, w_i) * light
// term, RGB, times the shift's Jacobian at each vertex (integrator/vertex.glsl: 1 for media). A
// vertex with zero density (or outside the volume) makes f = 0: the shift fails. A path ending in
// emission has sigma_a(x_n) Le(x_n) in place of sigma_s(x_n) and the light term.
vec3 rs_path_contribution(RsDomain D, uint set, uint pixelIndex, bool unbiased, inout RngState rng) {
  RsPathHead h = rs_load_head(set, pixelIndex);
  uint n = h.vertexCount;
  if (n == 0u) return vec3(0.0f);
  uint base = rs_bounce_base(set, pixelIndex);
  vec3 x = D.origin;
  vec3 w = rs_domain_dir(D, rs_unpack_uv(h.uv));
  float t = h.t1;
  vec3 f = vec3(1.0f);
  uint kind = VERTEX_MEDIUM;
  // A path ending in emission: its last vertex absorbs (sigma_a Le = sigma_t (1 - albedo) Le)
  // instead of scattering towards a light.
  bool emits = false;
#ifdef PLUME_HAS_EMISSION
  emits = h.light == RS_LIGHT_EMISSION;
#endif
  for (uint i = 1u; i <= n; ++i) {
    if (i >= 2u) {
      vec4 b = rsBounces[base + i - 2u];
      f *= vtx_scatter(kind, w, b.xyz);
      w = b.xyz;
      t = b.w;
    }
    kind = vtx_kind(h.kinds, i);
    float tr = rs_transmittance(D.v, x, w, t, unbiased, rng);
    x += t * w;
    float sigma = vol_sigma_t_world(D.v, x);
    if (!(sigma > 0.0f)) return vec3(0.0f);
    vec3 a = vtx_albedo(kind);
    if (emits && i == n) a = vec3(1.0f) - a;
    f *= tr * sigma * a * vtx_shift_jacobian(kind);
  }
#ifdef PLUME_HAS_EMISSION
  if (emits) return f * vol_emitted_radiance_world(D.v, x);
#endif
  return f * rs_light_term(D.v, kind, h.light, h.lightSample, x, w, unbiased, rng);
}

// The target function p̂_D(y): deterministic (no random numbers are drawn on this path).
float rs_target(RsDomain D, uint set, uint pixelIndex) {
  RngState unused = RngState(uvec4(0u), 0u);  // never drawn from: no hash to pay for
  return rs_luminance(rs_path_contribution(D, set, pixelIndex, false, unused));
}

#endif
