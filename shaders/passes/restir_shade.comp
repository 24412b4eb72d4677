// ReSTIR pass 4 (DESIGN §4.2 step 7): final shading of reservoir set push.inSet, accumulated into
// the output (push.restartAccumulation = 1: the first sample of the accumulation, which restarts it).
#version 450
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;  // over a list of pixels (rs_dispatch_pixel)

#include "../restir/bindings.glsl"
#include "../restir/bridge.glsl"
#include "../restir/shade.glsl"
#include "../volume/loop_guard.glsl"

void main() {
  rs_load_params();
  uvec2 pixel;
  if (!rs_dispatch_pixel(pixel)) return;
  rs_shade_pixel(pixel, push.inSet, push.restartAccumulation != 0u);
  loop_guard_check(frame.loopProbe);
}
