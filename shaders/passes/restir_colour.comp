// ReSTIR's colour weights (restir/colour.glsl), in the frames where they change
// (Restir::fillFrame), before the candidates: push.colourStep 0, 1 or 3 walks each pixel's
// estimate (0: afresh; 1: into the mean of the walks since the camera and the grid last changed;
// 3: of the last few, while the camera moves), 2 writes the weights of slot rsp.colourSet from
// the estimates (a dispatch of its own: it reads the neighbours').
#version 450
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;  // over a list of pixels (rs_dispatch_pixel)

#define PLUME_RS_TAIL 1  // the tail's walk (restir/shade.glsl) is the estimate's
#include "../restir/bindings.glsl"
#include "../restir/bridge.glsl"
#include "../restir/shade.glsl"
#include "../restir/colour.glsl"
#include "../volume/loop_guard.glsl"

void main() {
  rs_load_params();
  uvec2 pixel;
  if (!rs_dispatch_pixel(pixel)) return;
  uint index = pixel.y * frame.size.x + pixel.x;
  if (push.colourStep == 2u) {
    vec3 k = rs_colour_weights(pixel);
#if PLUME_RS_COLOUR_ALTERNATE  // tests only (RestirOptions::colourAlternate)
    k = rsp.colourSet == 0u ? vec3(0.5f, 0.3f, 0.2f) : vec3(0.2f, 0.3f, 0.5f);
#endif
    rs_set_state(rs_colour_slot(rsp.colourSet, index), vec4(k, 0.0f));
  } else {
#if PLUME_RS_COLOUR_TARGET
    rs_colour_estimate(pixel, index, push.colourStep == 0u ? 0.0f : push.colourStep == 1u ? 1e6f : 3.0f);
#endif
  }
  loop_guard_check(frame.loopProbe);
}
