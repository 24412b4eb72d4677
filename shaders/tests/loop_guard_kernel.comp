// tests/test_loop_guard.cpp: a loop of pc.iterations iterations per invocation, its count
// written out, then the driver-loop-limit probe (volume/loop_guard.glsl).
#version 450
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;

#include "../shared/gpu_types.h"
#include "../volume/bindings.glsl"
#include "../volume/loop_guard.glsl"

const uint BIND_TEST_RESULTS = BIND_VOLUME_COUNTERS + 1u;
layout(std430, binding = BIND_TEST_RESULTS) writeonly buffer Results { uint counted[]; };
layout(push_constant) uniform Push { uint iterations; uint probe; } pc;

void main() {
  vol_load_params();
  uint n = 0u;
  for (uint i = 0u; i < pc.iterations; ++i) n += 1u;
  counted[gl_GlobalInvocationID.x] = n;
  loop_guard_check(pc.probe);
}
