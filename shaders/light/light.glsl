// The one light module (DESIGN §2 "Lights"): per light type a direction sample at a point, the
// connection along a sampled direction (direction, distance, emitted term) and the pdf of the
// sample, behind one dispatcher on GpuLight.type; and the radiance an escaping ray sees. Used by
// the path tracer's next-event estimation, ReSTIR's light samples and final shading.
// Light types missing from the scene are compiled out (PLUME_HAS_SUN, _POINT, _ENV, _ENV_MAP;
// PLUME_HAS_ENV is defined for either kind of environment, PLUME_HAS_ENV_MAP for a map).
// Conventions: w points from the shaded point towards the light; a path arriving along wIn
// scatters light from w with cosTheta = dot(w, wIn) (shared/phase.h).
// Requires scene/bindings.glsl.
#ifndef PLUME_LIGHT_GLSL
#define PLUME_LIGHT_GLSL

#include "../shared/dda.h"
#include "../shared/phase.h"
#include "../shared/sampling.h"

// Whether the light's sample is a direction drawn from u (a sun's disk, the environment); the
// others (a delta sun, a point light) are fixed by the light and the shaded point alone.
bool light_samples_direction(GpuLight l) {
  return (l.type == LIGHT_SUN && l.versine > 0.0f) || l.type == LIGHT_ENVIRONMENT || l.type == LIGHT_ENV_MAP;
}

// A direction towards light l from x, for a path arriving along wIn at a medium of phase g: the
// sun's disk uniformly in its cone; a constant environment by phase sampling; an environment
// map from its texels' distribution (shared/envmap.h); a delta sun or a point light its only
// direction (u unused).
vec3 light_sample_dir(GpuLight l, vec3 x, vec3 wIn, float g, vec2 u) {
#ifdef PLUME_HAS_SUN
  if (l.type == LIGHT_SUN) return l.versine <= 0.0f ? l.dirOrPos : smp_uniform_cone(l.dirOrPos, l.versine, u);
#endif
#ifdef PLUME_HAS_POINT
  if (l.type == LIGHT_POINT) return l.dirOrPos - x;
#endif
#ifdef PLUME_HAS_ENV
  if (l.type == LIGHT_ENVIRONMENT) return ph_hg_sample(wIn, g, u);
#endif
#ifdef PLUME_HAS_ENV_MAP
  if (l.type == LIGHT_ENV_MAP) return env_sample(envMap, u);
#endif
  return vec3(0.0f, 0.0f, 1.0f);
}

// The connection from x to light l along a sampled direction wSampled: the unit direction w, the
// distance (DDA_INF for distant lights) and the emitted term: sun delta: irradiance; sun disk and
// environment: radiance (per unit solid angle of w; a map's texel); point: intensity / r². False where there is
// no light that way (a direction outside the sun's disk, up to its float encoding's rounding).
bool light_connect(GpuLight l, vec3 x, vec3 wSampled, out vec3 w, out float dist, out vec3 Le) {
  dist = DDA_INF;
  Le = l.emission;
  w = wSampled;
#ifdef PLUME_HAS_SUN
  if (l.type == LIGHT_SUN) {
    if (l.versine <= 0.0f) {
      w = l.dirOrPos;
      return true;
    }
    return smp_versine(w, l.dirOrPos) <= l.versine * 1.001f;
  }
#endif
#ifdef PLUME_HAS_POINT
  if (l.type == LIGHT_POINT) {
    vec3 toL = l.dirOrPos - x;
    dist = length(toL);
    if (!(dist > 0.0f)) return false;
    w = toL / dist;
    Le = l.emission / (dist * dist);
    return true;
  }
#endif
#ifdef PLUME_HAS_ENV
  if (l.type == LIGHT_ENVIRONMENT) return true;
#endif
#ifdef PLUME_HAS_ENV_MAP
  if (l.type == LIGHT_ENV_MAP) {
    Le = env_radiance(envMap, w);
    return true;
  }
#endif
  return false;
}

// The pdf of light_sample_dir's direction w (solid angle; 1 for the delta lights, whose emitted
// term already is the integral over their one direction).
float light_pdf(GpuLight l, vec3 w, vec3 wIn, float g) {
#ifdef PLUME_HAS_SUN
  if (l.type == LIGHT_SUN) {
    if (l.versine <= 0.0f) return 1.0f;
    return smp_versine(w, l.dirOrPos) <= l.versine * 1.001f ? smp_uniform_cone_pdf(l.versine) : 0.0f;
  }
#endif
#ifdef PLUME_HAS_ENV
  if (l.type == LIGHT_ENVIRONMENT) return ph_hg(dot(w, wIn), g);
#endif
#ifdef PLUME_HAS_ENV_MAP
  if (l.type == LIGHT_ENV_MAP) return env_pdf(envMap, w);
#endif
  return 1.0f;
}

// The radiance a ray leaving the scene along dir (unit) carries back: every environment light's.
vec3 light_escaped(vec3 dir) {
  vec3 sum = vec3(0.0f);
#ifdef PLUME_HAS_ENV
  for (uint i = 0u; i < frame.lightCount; ++i) {
    GpuLight l = light_at(i);
    if (l.type == LIGHT_ENVIRONMENT) sum += l.emission;
  }
#endif
#ifdef PLUME_HAS_ENV_MAP
  sum += env_radiance(envMap, dir);  // at most one map (scene/scene.cpp)
#endif
  return sum;
}

#endif
