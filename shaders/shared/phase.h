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

// p(cosTheta) per steradian; integrates to 1 over the sphere.
PLUME_FN float ph_hg(float cosTheta, float g) {
  // 1 + g^2 - 2 g cosTheta, written as a sum of non-negative terms so that it keeps full
  // precision at the peak (cosTheta -> sign(g)); the naive form loses ~1e-3 relative at g = 0.99.
  float denom = g >= 0.0f ? (1.0f - g) * (1.0f - g) + 2.0f * g * (1.0f - cosTheta)
                          : (1.0f + g) * (1.0f + g) - 2.0f * g * (1.0f + cosTheta);
  denom = max(denom, 1e-12f);
  return PLUME_INV_4PI * (1.0f - g * g) / (denom * sqrt(denom));
}

// Inverts the HG CDF in cosTheta: u = 0 gives -1, u = 1 gives +1. Also returns
// sin^2(theta) = (1 - cosTheta)(1 + cosTheta). With s = (1 - g^2) / d, d = 1 - g + 2 g u, the
// inverse cosTheta = (1 + g^2 - s^2) / (2g) is rewritten without cancellation or division by g:
//   1 - cosTheta = (1 - g)(1 - u)(s + 1 - g) / d,   1 + cosTheta = (1 + g) u (s + 1 + g) / d.
// (The direct form rounds 1 - cosTheta to 0 for ~3e-4 of the samples at g = 0.99, sending them
// exactly along wi; it also needed an isotropic branch whose pdf was not ph_hg.)
PLUME_FN float ph_hg_sample_cos_sin2(float g, float u, OUT(float) sin2Theta) {
  float d = 1.0f - g + 2.0f * g * u;
  float s = (1.0f - g * g) / d;
  float oneMinusCos = (1.0f - g) * (1.0f - u) * (s + 1.0f - g) / d;
  float onePlusCos = (1.0f + g) * u * (s + 1.0f + g) / d;
  sin2Theta = max(0.0f, oneMinusCos * onePlusCos);
  float cosTheta = oneMinusCos < onePlusCos ? 1.0f - oneMinusCos : onePlusCos - 1.0f;
  return clamp(cosTheta, -1.0f, 1.0f);
}

PLUME_FN float ph_hg_sample_cos(float g, float u) {
  float sin2Theta;
  return ph_hg_sample_cos_sin2(g, u, sin2Theta);
}

// Samples wo around wi; the pdf is ph_hg(dot(wi, wo), g).
PLUME_FN vec3 ph_hg_sample(vec3 wi, float g, vec2 u) {
  float sin2Theta;
  float cosTheta = ph_hg_sample_cos_sin2(g, u.x, sin2Theta);
  float sinTheta = sqrt(sin2Theta);
  float phi = 2.0f * PLUME_PI * u.y;
  vec3 b1;
  vec3 b2;
  plume_onb(wi, b1, b2);
  return normalize(sinTheta * cos(phi) * b1 + sinTheta * sin(phi) * b2 + cosTheta * wi);
}

PLUME_NS_END

#endif
