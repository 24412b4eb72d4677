// Next-event estimation at a medium vertex (the GPU twin of the reference's estimateDirect).
// `rayDir` is the path's propagation direction from the camera; light arriving from direction
// w scatters towards the camera with cosTheta = dot(w, rayDir) (shared/phase.h convention).
// Light types missing from the scene are compiled out (PLUME_HAS_SUN, _POINT, _ENV).
#ifndef PLUME_LIGHTS_GLSL
#define PLUME_LIGHTS_GLSL

#include "../shared/phase.h"
#include "../shared/sampling.h"

vec3 light_direct(GpuLight l, vec3 x, vec3 rayDir, float g, inout RngState rng) {
  uint type = uint(l.params.x);
#ifdef PLUME_HAS_SUN
  if (type == LIGHT_SUN) {
    float vMax = l.params.y;  // 1 - cos(angular radius); 0: a delta direction
    if (vMax <= 0.0f) {
      vec3 w = l.dirOrPos.xyz;
      return l.emission.rgb * ph_hg(dot(w, rayDir), g) * vol_ratio_tracking(x, w, DDA_INF, rng);
    }
    vec3 w = smp_uniform_cone(l.dirOrPos.xyz, vMax, rng_float2(rng));
    float tr = vol_ratio_tracking(x, w, DDA_INF, rng);
    return l.emission.rgb * ph_hg(dot(w, rayDir), g) * tr / smp_uniform_cone_pdf(vMax);
  }
#endif
#ifdef PLUME_HAS_POINT
  if (type == LIGHT_POINT) {
    vec3 toL = l.dirOrPos.xyz - x;
    float dist = length(toL);
    if (dist <= 0.0f) return vec3(0.0f);
    vec3 w = toL / dist;
    return l.emission.rgb / (dist * dist) * ph_hg(dot(w, rayDir), g) * vol_ratio_tracking(x, w, dist, rng);
  }
#endif
#ifdef PLUME_HAS_ENV
  if (type == LIGHT_ENVIRONMENT) {
    // Phase importance sampling: L * phase / pdf * T = L * T.
    vec3 w = ph_hg_sample(rayDir, g, rng_float2(rng));
    return l.emission.rgb * vol_ratio_tracking(x, w, DDA_INF, rng);
  }
#endif
  return vec3(0.0f);
}

#endif
