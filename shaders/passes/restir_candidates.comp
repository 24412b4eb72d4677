// ReSTIR pass 1 (DESIGN §4.2 step 1): candidate walks push.candidate .. of the M per pixel into
// reservoir set push.outSet, rsp.walksPerDispatch of them; the host dispatches it until all M are
// walked (restir/candidates.glsl).
#version 450
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 8, local_size_y = 8) in;

#include "../restir/bindings.glsl"
#include "../restir/bridge.glsl"
#include "../restir/candidates.glsl"
#include "../volume/loop_guard.glsl"

void main() {
  rs_load_params();
  uvec2 pixel = gl_GlobalInvocationID.xy;
  if (pixel.x >= frame.size.x || pixel.y >= frame.size.y) return;
  rs_candidate_walks(pixel, pixel.y * frame.size.x + pixel.x, push.outSet, push.candidate);
  loop_guard_check(frame.loopProbe);
}
