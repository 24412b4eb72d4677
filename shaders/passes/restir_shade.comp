// ReSTIR pass 4 (DESIGN §4.2 step 7): final shading of reservoir set push.sets.x into the output.
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
  rsOutput[index] = vec4(rs_shade(pixel, index, push.sets.x), 1.0f);
}
