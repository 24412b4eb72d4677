// Final shading (DESIGN §4.2 step 7): the selected path evaluated once with unbiased
// transmittance (residual ratio tracking on the fine grid, every segment and the light ray) times
// W = w_sum / p̂(Y); plus the radiance of the camera ray escaping the scene (light_escaped, also
// by residual ratio tracking) and the medium's emission seen directly, which no reservoir path
// covers; plus, when max_bounces exceeds the prefix K that reservoirs hold (or, in an emitting
// medium, max_bounces + 1 exceeds the emitting prefix rs_emission_vertices), the tail: the longer
// paths, path traced. Requires restir/bridge.glsl.
#ifndef PLUME_RESTIR_SHADE_GLSL
#define PLUME_RESTIR_SHADE_GLSL

#include "../shared/accumulate.h"

#ifdef PLUME_RS_TAIL
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
vec3 rs_tail(RsDomain D, inout RngState rng) {
  vec3 x = D.origin;
  vec3 w = rs_domain_dir(D, rng_float2(rng));  // its own sub-pixel position: pdf 1 on the pixel
  vec3 beta = vec3(1.0f);
  vec3 L = vec3(0.0f);
  float q = min(1.0f, plume_max3(vtx_albedo(VERTEX_MEDIUM)));
#ifdef PLUME_HAS_EMISSION
  uint emitting = rs_emission_vertices();
  uint segments = frame.maxBounces + 1u;
#else
  uint segments = frame.maxBounces;
#endif
  for (uint j = 1u; j <= segments; ++j) {
    float t;
#ifdef PLUME_HAS_EMISSION
    vec3 emitted;
    bool collided = vol_sample_collision_emitting(x, w, DDA_INF, rng, t, emitted);
    if (j > emitting) L += beta * (vec3(1.0f) - vtx_albedo(VERTEX_MEDIUM)) * emitted;
    if (!collided || j > frame.maxBounces) break;
#else
    if (!vol_sample_collision(x, w, DDA_INF, rng, t)) break;
#endif
    x += t * w;
    beta *= vtx_albedo(VERTEX_MEDIUM);
    if (j > rsp.prefixVertices) {
      uvec4 h = rng_next4(rng);
      uint light;
      vec2 ls;
      float pl = rs_sample_light(w, vec3(rng_to_float(h.x), rng_to_float(h.y), rng_to_float(h.z)), light, ls);
      if (pl > 0.0f) L += beta * rs_light_term(VOL_CURRENT, VERTEX_MEDIUM, light, ls, x, w, true, rng) / pl;
    }
    if (j == segments) break;
    if (j >= frame.rrStartBounce) {
      if (rng_float(rng) >= q) break;
      beta /= q;
    }
    w = vtx_sample(VERTEX_MEDIUM, w, rng_float2(rng));
  }
  return L;
}
#endif

vec3 rs_shade(uvec2 pixel, uint pixelIndex, uint set) {
  RsDomain D = rs_current_domain(pixel);
  RngState rng = rng_init(pixel, frame.frameKey, RNG_STREAM_SHADING, frame.seed);
  RsReservoir r = rs_load(set, pixelIndex);
  vec3 L = vec3(0.0f);
  if (r.W > 0.0f) L += r.W * rs_path_contribution(D, set, pixelIndex, true, rng);
#ifdef PLUME_HAS_ENV
  vec3 dir = rs_domain_dir(D, rng_float2(rng));
  L += light_escaped(dir) * vol_residual_tr(D.origin, dir, DDA_INF, rng);
#endif
#ifdef PLUME_HAS_EMISSION
  // The medium's emission seen directly (paths of one vertex, which no candidate ends with),
  // gathered along a camera ray with ratio tracking's running transmittance (vol_emission_along:
  // no collision is needed, so the whole ray counts). A self-lit fire is mostly this term; the
  // reservoirs carry the light the fire and the lights scatter.
  L += (vec3(1.0f) - vtx_albedo(VERTEX_MEDIUM)) * vol_emission_along(D.origin, rs_domain_dir(D, rng_float2(rng)), DDA_INF, rng);
#endif
#ifdef PLUME_RS_TAIL
  L += rs_tail(D, rng);
#endif
  return L;
}

// Final shading of `pixel` from reservoir set `set`, into the accumulation (restart: the first
// sample of a new accumulation).
void rs_shade_pixel(uvec2 pixel, uint set, bool restart) {
  uint index = pixel.y * frame.size.x + pixel.x;
  vec3 L = rs_shade(pixel, index, set);
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

#endif
