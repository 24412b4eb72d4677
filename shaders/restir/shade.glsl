// Final shading (DESIGN §4.2 step 7): the selected path evaluated once with unbiased
// transmittance (residual ratio tracking on the fine grid, every segment and the light ray) times
// W = w_sum / p̂(Y); plus the radiance of the camera ray escaping the scene (light_escaped, also
// by residual ratio tracking) and the medium's emission seen directly, which no reservoir path
// covers. Requires restir/bridge.glsl.
#ifndef PLUME_RESTIR_SHADE_GLSL
#define PLUME_RESTIR_SHADE_GLSL

#include "../shared/accumulate.h"

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
