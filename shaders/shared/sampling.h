// Plain sampling routines shared by the CPU reference, the GPU passes and the tests: free-flight
// distances, uniform sphere, uniform cone (the sun's disk). Each returns its pdf's ingredients
// in closed form so the chi-square tests can check it.
#ifndef PLUME_SHARED_SAMPLING_H
#define PLUME_SHARED_SAMPLING_H

#include "common.h"

PLUME_NS_BEGIN

// Exponential free flight in a medium of extinction sigma: pdf sigma * exp(-sigma t).
// u in [0,1); 1 - u is in (0,1] so the log is finite.
PLUME_FN float smp_exponential(float sigma, float u) { return -log(1.0f - u) / sigma; }

// Uniform direction on the unit sphere; pdf 1/(4 pi).
PLUME_FN vec3 smp_uniform_sphere(vec2 u) {
  float z = 1.0f - 2.0f * u.x;
  float r = sqrt(max(0.0f, 1.0f - z * z));
  float phi = 2.0f * PLUME_PI * u.y;
  return vec3(r * cos(phi), r * sin(phi), z);
}

// Uniform direction in the cone of half-angle alpha around unit `axis`, given by its versine
// vMax = 1 - cos(alpha) (compute it as 2 sin^2(alpha / 2) in double: for the sun's disk,
// 1 - cos(alpha) ~ 1e-5, and 1 - float(cos(alpha)) is off by up to 0.5%, which would bias the
// disk's solid angle); pdf 1 / (2 pi vMax). vMax = 0 returns the axis (a delta direction).
// sinTheta comes from 1 - cosTheta directly: the form sqrt(1 - cosTheta^2) quantises theta to
// ~180 rings for the sun and puts ~0.3% of samples on the axis.
PLUME_FN vec3 smp_uniform_cone(vec3 axis, float vMax, vec2 u) {
  float oneMinusCos = u.x * vMax;
  float cosTheta = 1.0f - oneMinusCos;
  float sinTheta = sqrt(max(0.0f, oneMinusCos * (2.0f - oneMinusCos)));
  float phi = 2.0f * PLUME_PI * u.y;
  vec3 b1;
  vec3 b2;
  plume_onb(axis, b1, b2);
  return normalize(sinTheta * cos(phi) * b1 + sinTheta * sin(phi) * b2 + cosTheta * axis);
}

PLUME_FN float smp_uniform_cone_pdf(float vMax) { return 1.0f / (2.0f * PLUME_PI * vMax); }

// Versine of the angle between unit vectors a and b, 1 - dot(a, b), computed as |a - b|^2 / 2
// so that it keeps its precision for tiny angles.
PLUME_FN float smp_versine(vec3 a, vec3 b) {
  vec3 d = a - b;
  return 0.5f * dot(d, d);
}

PLUME_NS_END

#endif
