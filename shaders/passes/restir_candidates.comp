// ReSTIR pass 1 (DESIGN §4.2 step 1): candidate walks push.candidate .. of the M per pixel into
// reservoir set push.outSet, rsp.walksPerDispatch of them; the host dispatches it until all M are
// walked (restir/candidates.glsl).
#version 450
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;  // over a list of pixels (rs_dispatch_pixel)

#include "../restir/bindings.glsl"
#include "../restir/bridge.glsl"
#include "../restir/candidates.glsl"
#include "../volume/loop_guard.glsl"

void main() {
  rs_load_params();
  uvec2 pixel;
  if (!rs_dispatch_pixel(pixel)) return;
  rs_candidate_walks(pixel, pixel.y * frame.size.x + pixel.x, push.outSet, push.candidate);
  loop_guard_check(frame.loopProbe);
}
