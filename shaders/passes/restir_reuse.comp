// ReSTIR passes 2 and 3 (DESIGN §4.2 steps 5-6): temporal reuse (PLUME_RS_TEMPORAL 1: the
// canonical set push.inSet and the history set push.historySet at the
// reprojected pixel, confidence capped) or one spatial round (k neighbours of set push.inSet
// within the radius, drawn from the pixel and the round only). Output: set push.outSet.
#version 450
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;  // over a list of pixels (rs_dispatch_pixel)

#include "../restir/bindings.glsl"
#include "../restir/bridge.glsl"
#include "../restir/reuse.glsl"
#include "../volume/loop_guard.glsl"

#ifndef PLUME_RS_TEMPORAL
#define PLUME_RS_TEMPORAL 0
#endif

// Compiled twice: PLUME_RS_TEMPORAL 1 (temporal reuse) or 0 (a spatial round), so that each
// pipeline holds only its own code (see restir/reuse.glsl on PLUME_RS_MIS).
void main() {
  rs_load_params();
  uvec2 pixel;
  if (!rs_dispatch_pixel(pixel)) return;
  rs_reuse_pixel(pixel, pixel.y * frame.size.x + pixel.x, PLUME_RS_TEMPORAL != 0, push.spatialRound, push.inSet,
                 push.historySet, push.outSet);
  loop_guard_check(frame.loopProbe);
}
