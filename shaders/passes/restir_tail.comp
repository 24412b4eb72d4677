// ReSTIR pass 4b (DESIGN §4.2 step 7, with a tail): one dispatch of final shading's tail, at most
// RS_TAIL_SEGMENTS segments of each pixel's walk (restir/shade.glsl); the host dispatches it until
// every walk has ended (Restir::render: push.countAlive asks the last dispatch of a submit to count
// the walks still alive). push.restartAccumulation as for pass 4.
#version 450
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;  // over a list of pixels (rs_dispatch_pixel)

#define PLUME_RS_TAIL 1
#include "../restir/bindings.glsl"
#include "../restir/bridge.glsl"
#include "../restir/shade.glsl"
#include "../volume/loop_guard.glsl"

void main() {
  rs_load_params();
  uvec2 pixel;
  if (!rs_dispatch_pixel(pixel)) return;
  bool alive = rs_tail_pixel(pixel, push.restartAccumulation != 0u);
  if (alive && push.countAlive != 0u) atomicAdd(rsCounters[RS_COUNTER_TAIL_ALIVE], 1u);
  loop_guard_check(frame.loopProbe);
}
