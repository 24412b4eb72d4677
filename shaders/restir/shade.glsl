// Final shading (DESIGN §4.2 step 7): the selected path evaluated once with unbiased
// transmittance times W = w_sum / p̂(Y): residual ratio tracking against the mean field, whose
// transmittances of the path's segments are p̂'s own factors (so only the ratio of the fine ones
// to them is estimated, bridge.glsl rs_path_contribution), and on the light ray; plus the
// radiance of the camera ray escaping the scene (light_escaped, also by residual ratio tracking)
// and the medium's emission seen directly, which no reservoir path
// covers; with emissive surfaces, the lamps seen directly from their reservoir of their own; plus,
// when max_bounces exceeds the prefix K that reservoirs hold (or, in an emitting medium,
// max_bounces + 1 exceeds the emitting prefix rs_emission_vertices), the tail: the longer paths,
// path traced. Requires restir/bridge.glsl.
#ifndef PLUME_RESTIR_SHADE_GLSL
#define PLUME_RESTIR_SHADE_GLSL

#include "../shared/accumulate.h"

#ifdef PLUME_RS_TAIL
#include "../integrator/path.glsl"

// The tail (notes/restir.md "Any path length"): an independent path-traced estimate of the
// paths with more than K = rsp.prefixVertices scattering vertices (up to frame.maxBounces).
// Reservoirs only ever hold paths of at most K vertices, each ending in a light sample at its last
// vertex; this walk adds next-event estimation only at vertices K+1, K+2, ..., so every path
// length is counted exactly once. Delta tracking on the fine grid (weight albedo per real
// collision), HG sampling (weight 1), the candidates' Russian roulette, the candidates' light
// choice with unbiased transmittance (residual ratio tracking, rs_light_term). In an emitting
// medium the walk also gathers the emission along segment j (paths of j vertices, the last one
// emitting) for j > rs_emission_vertices(), the longest emitting path a reservoir holds, up to
// the segment after vertex max_bounces, as the path tracer does.
//
// The walk is resumable (lavapipe's loop budget, docs/architecture.md): final shading starts it
// (rs_tail_start) and each dispatch of passes/restir_tail.comp advances it by at most
// RS_TAIL_SEGMENTS segments (shared/restir_types.h; rs_tail_advance), its state in the pixel's
// slots past the accumulation (rs_tail_load / rs_tail_store), until it ends and the pixel's
// sample, the terms of final shading plus the tail, is accumulated. The random stream is the
// shading stream, continued across dispatches: the same draws in the same order as one walk in
// one invocation.

struct RsTail {
  vec3 x;
  uint j;  // the next segment (1 = the camera ray's); 0: the walk has ended
  vec3 w;
  uint rngCounter;  // the shading stream's draws so far
  vec3 beta;
  float pdfDir;  // with surfaces: the density of w at the vertex that sampled it (vtx_at_pdf)
  vec3 L;       // the tail's radiance so far
  uint from;    // with surfaces: the triangle of the vertex that drew w (RS_TAIL_NO_SURFACE: none)
  vec3 shaded;  // final shading's other terms (rs_shade): the pixel's sample is shaded + L
};

const uint RS_TAIL_NO_SURFACE = 0xffffffffu;

// The walk's state: rs_state(rs_state_slot(pixel) + i), i < RS_STATE_SLOTS.
RsTail rs_tail_load(uint pixelIndex) {
  uint s = rs_state_slot(pixelIndex);
  vec4 a = rs_state(s), b = rs_state(s + 1u);
  vec4 c = rs_state(s + 2u);
  vec4 d = rs_state(s + 3u);
  return RsTail(a.xyz, floatBitsToUint(a.w), b.xyz, floatBitsToUint(b.w), c.xyz, c.w, d.xyz, floatBitsToUint(d.w),
                rs_state(s + 4u).xyz);
}

void rs_tail_store(uint pixelIndex, RsTail s) {
  uint i = rs_state_slot(pixelIndex);
  rs_set_state(i, vec4(s.x, uintBitsToFloat(s.j)));
  rs_set_state(i + 1u, vec4(s.w, uintBitsToFloat(s.rngCounter)));
  rs_set_state(i + 2u, vec4(s.beta, s.pdfDir));
  rs_set_state(i + 3u, vec4(s.L, uintBitsToFloat(s.from)));
  rs_set_state(i + 4u, vec4(s.shaded, 0.0f));
}

RsTail rs_tail_start(RsDomain D, vec3 shaded, inout RngState rng) {
  vec3 w = rs_domain_dir(D, rng_float2(rng));  // its own sub-pixel position: pdf 1 on the pixel
  return RsTail(D.origin, 1u, w, rng.counter, vec3(1.0f), 0.0f, vec3(0.0f), RS_TAIL_NO_SURFACE, shaded);
}

// Segment s.j of the walk and what its vertex adds; false when the walk ends there. The segment
// and the scattering at its vertex are the path tracer's steps (integrator/path.glsl): with
// surfaces the segment ends at the nearer of the medium's collision and the first surface, a
// vertex either way; NEE at either, BSDF sampling at a surface (weight f cos / pdf), and emitters
// reached both ways with the reservoirs' MIS weights (rs_emitter_weight).
// lightFrom, emissionFrom: the vertices after which it takes light samples and gathers emission
// (final shading's tail: those the reservoirs do not hold; restir/colour.glsl's estimate: 0, 0);
// unbiased: the light rays' transmittance by residual ratio tracking (the tail's) or the target's
// midpoint rule (the colour estimate's: any function of the walk serves it, and the cheap one).
bool rs_tail_segment(inout RsTail s, inout RngState rng, uint lightFrom, uint emissionFrom, bool unbiased) {
  uint j = s.j;
#ifdef RS_ENDS_IN_EMISSION
  uint emitting = emissionFrom;
  uint segments = frame.maxBounces + 1u;
#else
  uint segments = frame.maxBounces;
#endif
  PathSegment seg = path_segment(s.x, s.w, rng);
#ifdef PLUME_HAS_EMISSION
  if (j > emitting) s.L += path_emission(seg, s.beta);
#endif
#ifdef PLUME_HAS_EMITTERS
  // An emitter hit by the direction sampled at vertex j - 1 (its MIS part; the reservoirs hold
  // those of segments up to rs_emission_vertices).
  if (path_hits_surface(seg) && j > emitting) {
    vec3 receiver = s.from != RS_TAIL_NO_SURFACE ? surf_receiver(s.from, s.w) : vec3(0.0f);
    s.L += s.beta * rs_emitter_hit(s.pdfDir, seg.hit.prim, s.x, receiver, s.w, seg.t);
  }
#endif
  if (!path_has_vertex(seg)) return false;
#ifdef RS_ENDS_IN_EMISSION
  if (j > frame.maxBounces) return false;
#endif
  PathVertex vx = path_vertex(seg, s.x, s.w, s.beta);
  if (j > lightFrom) {
    uvec4 h = rng_next4(rng);
    uint light;
    vec2 ls;
    uint prim;
    float pl = rs_sample_light(vx, vec3(rng_to_float(h.x), rng_to_float(h.y), rng_to_float(h.z)), rng, light, ls, prim);
    if (pl > 0.0f) s.L += s.beta * rs_light_term(VOL_CURRENT, vx, light, ls, prim, unbiased, rng) / pl;
  }
  if (j == segments) return false;
  // The candidates' roulette: on the albedo, not the throughput.
  if (!path_roulette(j, min(1.0f, plume_max3(vtx_albedo(VERTEX_MEDIUM))), rng, s.beta)) return false;
#ifdef PLUME_HAS_SURFACES
  float pdf;
  if (!path_scatter(vx, rng_float2(rng), s.beta, s.x, s.w, pdf)) return false;
  s.pdfDir = vtx_at_pdf(vx, s.w);  // evaluated as the reservoirs' emitter hits evaluate it
  s.from = vx.kind == VERTEX_SURFACE ? vx.prim : RS_TAIL_NO_SURFACE;
#else
  // The phase's sample as such (vtx_at_sample normalises it once more, and evaluates a pdf the
  // walk has no use for without emitters).
  s.w = vtx_sample(VERTEX_MEDIUM, s.w, rng_float2(rng));
#endif
  s.j = j + 1u;
  return true;
}

// At most RS_TAIL_SEGMENTS segments of the walk; true when it has ended.
bool rs_tail_advance(inout RsTail s, inout RngState rng) {
#ifdef RS_ENDS_IN_EMISSION
  uint emissionFrom = rs_emission_vertices();
#else
  uint emissionFrom = 0u;
#endif
  for (uint n = 0u; n < RS_TAIL_SEGMENTS; ++n) {
    if (!rs_tail_segment(s, rng, rsp.prefixVertices, emissionFrom, true)) {
      s.j = 0u;
      return true;
    }
  }
  return false;
}
#endif

// Final shading's terms but the tail, drawn from `rng` (the pixel's shading stream).
vec3 rs_shade(RsDomain D, uint pixelIndex, uint set, inout RngState rng) {
  vec3 L = vec3(0.0f);
  // Each class's reservoir (bridge.glsl PLUME_RS_CLASSES: set, set + RS_SETS), its estimate added.
  for (uint c = 0u; c < uint(PLUME_RS_CLASSES); ++c) {
    uint s = set + c * RS_SETS;
    RsReservoir r = rs_load(s, pixelIndex);
    if (!(r.W > 0.0f)) continue;
    // f without the segments' transmittances, whose target product is p̂ / lum(f) (the
    // reservoir's p̂ is the target of its path in this domain: candidates.glsl, reuse.glsl), and
    // the estimate of the fine transmittances' ratio to the target's (bridge.glsl).
    float est;
    float mis;
    vec3 f = rs_path_contribution(D, s, pixelIndex, true, rng, est, mis);
    float lum = rs_weigh(D.k, f);
    if (lum > 0.0f) L += (r.W * r.p_hat / lum) * est * mis * f;
  }
#ifdef PLUME_HAS_EMITTERS
  // The lamps seen directly: their reservoir's sample (restir/candidates.glsl rs_lamp_reservoir),
  // W Le T along its ray, T by residual ratio tracking.
  vec4 lamp = rs_state(rs_lamp_slot(rsp.lampSet, pixelIndex));
  if (lamp.x > 0.0f) {
    vec3 dirL = rs_domain_dir(D, rs_unpack_uv(floatBitsToUint(lamp.z)));
    BvhHit hitL = bvh_closest(D.origin, dirL, 0.0f, SURF_FAR);
    if (hitL.prim != BVH_NONE) {
      vec3 Le = surf_emitted(hitL.prim, surf_normal(hitL.prim), dirL);
      if (Le.x > 0.0f || Le.y > 0.0f || Le.z > 0.0f) L += lamp.x * Le * vol_residual_tr(D.origin, dirL, hitL.t, rng);
    }
  }
#endif
#ifdef PLUME_HAS_ENV
  // The camera ray escaping to the environment (a surface blocks it): one-segment paths, which
  // no candidate ends with.
  vec3 dir = rs_domain_dir(D, rng_float2(rng));
#ifdef PLUME_HAS_SURFACES
  BvhHit hit = bvh_closest(D.origin, dir, 0.0f, SURF_FAR);
  if (hit.prim == BVH_NONE) L += light_escaped(dir) * vol_residual_tr(D.origin, dir, DDA_INF, rng);
#else
  L += light_escaped(dir) * vol_residual_tr(D.origin, dir, DDA_INF, rng);
#endif
#endif
#ifdef PLUME_HAS_EMISSION
  // The medium's emission seen directly (paths of one vertex, which no candidate ends with),
  // gathered along a camera ray with ratio tracking's running transmittance (vol_emission_along:
  // no collision is needed, so the whole ray counts, up to the first surface). A self-lit fire is
  // mostly this term; the reservoirs carry the light the fire and the lights scatter.
  vec3 dirE = rs_domain_dir(D, rng_float2(rng));
  float tEnd = DDA_INF;
#ifdef PLUME_HAS_SURFACES
  BvhHit hitE = bvh_closest(D.origin, dirE, 0.0f, SURF_FAR);
  if (hitE.prim != BVH_NONE) tEnd = hitE.t;
#endif
  L += (vec3(1.0f) - vtx_albedo(VERTEX_MEDIUM)) * vol_emission_along(D.origin, dirE, tEnd, rng);
#endif
  return L;
}

// The pixel's sample L into the accumulation (restart: the first sample of a new accumulation).
void rs_accumulate(uint index, vec3 L, bool restart) {
  if (restart) {
    rsOutput[2u * index] = vec4(L, 1.0f);
    rsOutput[2u * index + 1u] = vec4(0.0f);
    return;
  }
  vec4 a = rsOutput[2u * index];
  vec3 m2 = rsOutput[2u * index + 1u].rgb;
  acc_merge(a, m2, L, vec3(0.0f), 1.0f);
  rsOutput[2u * index] = a;
  rsOutput[2u * index + 1u] = vec4(m2, 0.0f);
}

RngState rs_shading_rng(uvec2 pixel) { return rng_init(pixel, frame.frameKey, RNG_STREAM_SHADING, frame.seed); }

// Final shading of `pixel` from reservoir set `set`, into the accumulation; with a tail, the
// tail's walk is started instead and the sample is accumulated when it ends (rs_tail_pixel).
void rs_shade_pixel(uvec2 pixel, uint set, bool restart) {
  uint index = pixel.y * frame.size.x + pixel.x;
  RsDomain D = rs_current_domain(pixel);
  RngState rng = rs_shading_rng(pixel);
#ifdef PLUME_RS_OUTSIDE
  // The variant for pixels whose camera rays miss the volume (render/pixel_order.h; scenes
  // without surfaces): their reservoirs are empty (restir/candidates.glsl, reuse.glsl), the camera
  // ray escapes with transmittance 1 and meets no emission, and the tail's first segment ends
  // it: the sample is the environment along the same ray rs_shade draws.
  vec3 L = vec3(0.0f);
#ifdef PLUME_HAS_ENV
  L += light_escaped(rs_domain_dir(D, rng_float2(rng)));
#endif
  rs_accumulate(index, L, restart);
#else
  vec3 L = rs_shade(D, index, set, rng);
#ifdef PLUME_RS_TAIL
  rs_tail_store(index, rs_tail_start(D, L, rng));
#else
  rs_accumulate(index, L, restart);
#endif
#endif
}

#ifdef PLUME_RS_TAIL
// One dispatch of the tail's walk of `pixel` (passes/restir_tail.comp); the sample is accumulated
// once the walk has ended. Returns whether the walk is still alive after this dispatch.
bool rs_tail_pixel(uvec2 pixel, bool restart) {
  uint index = pixel.y * frame.size.x + pixel.x;
  RsTail s = rs_tail_load(index);
  if (s.j == 0u) return false;  // ended in an earlier dispatch
  RngState rng = rs_shading_rng(pixel);
  rng.counter = s.rngCounter;
  bool ended = rs_tail_advance(s, rng);
  s.rngCounter = rng.counter;
  if (ended) rs_accumulate(index, s.shaded + s.L, restart);
  rs_tail_store(index, s);
  return !ended;
}
#endif

#endif
