// Henyey–Greenstein phase function, evaluated and sampled in one place (DESIGN §2).
// Direction convention: both directions are *propagation* directions. `wi` is the direction
// the light (or the path, traced from the camera, reversed consistently) travels before the
// scattering event and `wo` after it; cosTheta = dot(wi, wo). g > 0 scatters forward
// (wo close to wi), g < 0 backward. The function is symmetric, so a path traced from the
// camera uses the same formula with its own ray directions.
#ifndef PLUME_SHARED_PHASE_H
#define PLUME_SHARED_PHASE_H

#include "common.h"

PLUME_NS_BEGIN

// Below this |g| the isotropic formulas are used (the HG expressions lose precision at g -> 0).
const float PH_ISOTROPIC_EPS = 1e-3f;

// p(cosTheta) per steradian; integrates to 1 over the sphere.
PLUME_FN float ph_hg(float cosTheta, float g) {
  float denom = 1.0f + g * g - 2.0f * g * cosTheta;
  denom = max(denom, 1e-12f);
  return PLUME_INV_4PI * (1.0f - g * g) / (denom * sqrt(denom));
}

// Inverts the HG CDF in cosTheta: u = 0 gives -1, u = 1 gives +1.
PLUME_FN float ph_hg_sample_cos(float g, float u) {
  if (abs(g) < PH_ISOTROPIC_EPS) return clamp(1.0f - 2.0f * (1.0f - u), -1.0f, 1.0f);
  float s = (1.0f - g * g) / (1.0f - g + 2.0f * g * u);
  return clamp((1.0f + g * g - s * s) / (2.0f * g), -1.0f, 1.0f);
}

// Samples wo around wi; the pdf is ph_hg(dot(wi, wo), g).
PLUME_FN vec3 ph_hg_sample(vec3 wi, float g, vec2 u) {
  float cosTheta = ph_hg_sample_cos(g, u.x);
  float sinTheta = sqrt(max(0.0f, 1.0f - cosTheta * cosTheta));
  float phi = 2.0f * PLUME_PI * u.y;
  vec3 b1;
  vec3 b2;
  plume_onb(wi, b1, b2);
  return normalize(sinTheta * cos(phi) * b1 + sinTheta * sin(phi) * b2 + cosTheta * wi);
}

PLUME_NS_END

#endif
