// ReSTIR pass 4 (DESIGN §4.2 step 7): final shading of reservoir set push.inSet, accumulated into
// the output (push.restartAccumulation = 1: the first sample of the accumulation, which restarts it).
#version 450
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 8, local_size_y = 8) in;

#include "../restir/bindings.glsl"
#include "../restir/bridge.glsl"
#include "../restir/shade.glsl"
#include "../shared/accumulate.h"

void main() {
  uvec2 pixel = gl_GlobalInvocationID.xy;
  if (pixel.x >= frame.size.x || pixel.y >= frame.size.y) return;
  uint index = pixel.y * frame.size.x + pixel.x;
  vec3 L = rs_shade(pixel, index, push.inSet);
  if (push.restartAccumulation != 0u) {
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
