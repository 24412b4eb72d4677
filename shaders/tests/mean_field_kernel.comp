// tests/test_mean_field_walk.cpp: ReSTIR's mean-field walks (volume/walk.glsl) on given rays,
// the optical depth (vol_mean_tau), a collision by delta tracking in the field (vol_mean_sample,
// its random stream keyed by the ray's index and seed) and the depth by the midpoint rule
// (vol_mean_tau_midpoints).
#version 450
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;

#define PLUME_VOL_MEAN_FIELD 1
#include "../shared/gpu_types.h"
#include "../volume/bindings.glsl"
#include "../volume/grid.glsl"
#include "../volume/walk.glsl"

const uint BIND_TEST_RAYS = BIND_MEAN_FIELD + 1u;
const uint BIND_TEST_RESULTS = BIND_MEAN_FIELD + 2u;
// Per ray two vec4: (origin, tMax), (unit direction, seed bits) in world space.
layout(std430, binding = BIND_TEST_RAYS) readonly buffer Rays { vec4 rays[]; };
// Per ray two vec4: (optical depth over (0, tMax), collision distance or -1, sigma at the
// collision, 0), (the midpoint rule's depth, 0, 0, 0).
layout(std430, binding = BIND_TEST_RESULTS) writeonly buffer Results { vec4 results[]; };
layout(push_constant) uniform Push { uint count; } pc;

void main() {
  vol_load_params();
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.count) return;
  vec4 a = rays[2u * i];
  vec4 b = rays[2u * i + 1u];
  float tau = vol_mean_tau(VOL_CURRENT, a.xyz, b.xyz, a.w);
  float t;
  float sigma;
  RngState rng = rng_init(uvec2(i, 0u), 0u, RNG_STREAM_TEST, floatBitsToUint(b.w));
  bool hit = vol_mean_sample(a.xyz, b.xyz, a.w, rng, t, sigma);
  results[2u * i] = vec4(tau, hit ? t : -1.0f, hit ? sigma : 0.0f, 0.0f);
  results[2u * i + 1u] = vec4(vol_mean_tau_midpoints(VOL_CURRENT, a.xyz, b.xyz, a.w), 0.0f, 0.0f, 0.0f);
}
