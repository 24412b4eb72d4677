// Tier c (DESIGN §7): shared/envmap.h on the device for tests/test_gpu_envmap.cpp, which runs the
// same functions compiled as C++ on the same map and inputs and compares. One thread per case.
#version 450
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;

#include "../shared/gpu_types.h"

layout(std430, binding = 0) readonly buffer EnvMapBuffer {
  GpuEnvMap envMap;
  float envData[];
};
#include "../shared/envmap.h"

struct EnvCase {
  vec4 u;     // xy: the sampler's random numbers
  vec4 dir;   // xyz: a unit world direction to look up
};
struct EnvResult {
  vec4 sampled;  // xyz: env_sample(u); w: env_pdf of it
  vec4 lookup;   // xyz: env_radiance(dir); w: env_pdf(dir)
};
layout(std430, binding = 1) readonly buffer Cases { EnvCase cases[]; };
layout(std430, binding = 2) writeonly buffer Results { EnvResult results[]; };
layout(push_constant) uniform Push { uint count; } pc;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.count) return;
  EnvCase c = cases[i];
  vec3 w = env_sample(envMap, c.u.xy);
  EnvResult o;
  o.sampled = vec4(w, env_pdf(envMap, w));
  o.lookup = vec4(env_radiance(envMap, c.dir.xyz), env_pdf(envMap, c.dir.xyz));
  results[i] = o;
}
