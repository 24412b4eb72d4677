// The path tracer's queue kernel (pt/wavefront.glsl), one invocation between the other kernels:
// the queue a kernel just filled becomes the next kernel's indirect dispatch, and the queue it
// consumed is emptied for the one after.
#version 450
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 1) in;

#include "../shared/bindings.h"
#include "../shared/pt_wave.h"

layout(std430, binding = BIND_PT_WAVE) buffer WaveBuffer { PtWave wave; };
layout(push_constant) uniform PtPushBlock { PtPush ptPush; };

uvec4 dispatch_of(uint n) { return uvec4((n + PT_WAVE_GROUP - 1u) / PT_WAVE_GROUP, 1u, 1u, n); }

void main() {
  if (ptPush.stage == PT_QUEUE_TO_SHADE) {
    wave.shadeArgs = dispatch_of(wave.shadeCount);
    wave.extendCount = 0u;
  } else {
    wave.extendArgs = dispatch_of(wave.extendCount);
    wave.shadeCount = 0u;
  }
}
