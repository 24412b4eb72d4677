// ReSTIR pass 4 (DESIGN §4.2 step 7): final shading of reservoir set push.sets.x, accumulated into
// the output (push.misc.y = 1: the first sample of the accumulation, which restarts it).
#version 450
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 8, local_size_y = 8) in;

#include "../restir/bindings.glsl"
#include "../volume/volume.glsl"
#include "../restir/coarse.glsl"
#include "../restir/bridge.glsl"
#include "../restir/shade.glsl"

void main() {
  uvec2 pixel = gl_GlobalInvocationID.xy;
  if (pixel.x >= frame.image.x || pixel.y >= frame.image.y) return;
  uint index = pixel.y * frame.image.x + pixel.x;
  vec3 L = rs_shade(pixel, index, push.sets.x);
  if (push.misc.y != 0u) {
    rsOutput[2u * index] = vec4(L, 1.0f);
    rsOutput[2u * index + 1u] = vec4(0.0f);
    return;
  }
  vec4 a = rsOutput[2u * index];  // Welford's update with one sample
  float n = a.w + 1.0f;
  vec3 d = L - a.rgb;
  vec3 mean = a.rgb + d / n;
  rsOutput[2u * index] = vec4(mean, n);
  rsOutput[2u * index + 1u] = vec4(rsOutput[2u * index + 1u].rgb + d * (L - mean), 0.0f);
}
