// ReSTIR's lamps seen directly (restir/candidates.glsl rs_lamp_reservoir): the lamp reservoir of
// every pixel in the list whose camera rays may meet an emitter's front (render/pixel_order.h
// emitterPixelRects), dense, so that a subgroup's lanes all trace, its rays drawn in the part of
// the pixel where they may; the candidates pass writes the others' empty reservoirs. Only for
// scenes with emissive surfaces.
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
  RngState rng = rng_init(pixel, frame.frameKey, RNG_STREAM_CANDIDATES, frame.seed);
  vec2 lo, hi;
  rs_lamp_rect(lo, hi);
  rs_lamp_reservoir(rs_current_domain(pixel), pixel.y * frame.size.x + pixel.x, lo, hi, rng);
  loop_guard_check(frame.loopProbe);
}
