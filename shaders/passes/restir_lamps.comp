// ReSTIR's lamps seen directly (restir/candidates.glsl rs_lamp_reservoir): the lamp reservoir of
// every pixel in the list whose camera rays may meet an emitter's front (render/pixel_order.h
// emitterPixelMask), dense, so that a subgroup's lanes all trace, its rays drawn on the projections
// of the emitter triangles the pixel may see (PLUME_RS_LAMP_TRIANGLES: emitterPixelTriangles) or in
// the rectangle of the pixel where they may be seen (emitterPixelRects); the candidates pass writes
// the others' empty reservoirs. Only for scenes with emissive surfaces.
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
  RsDomain D = rs_current_domain(pixel);
  uint uv;
  vec3 dirY;
  float tY;
#ifdef PLUME_RS_LAMP_TRIANGLES
  uint start, count;
  rs_lamp_triangles(start, count);
  RsReservoir r = rs_lamp_triangle_candidates(D, start, count, rng, uv, dirY, tY);
#else
  vec2 lo, hi;
  rs_lamp_rect(lo, hi);
  RsReservoir r = rs_lamp_rect_candidates(D, lo, hi, rng, uv, dirY, tY);
#endif
  rs_lamp_reservoir(D, pixel.y * frame.size.x + pixel.x, r, uv, dirY, tY, rng);
  loop_guard_check(frame.loopProbe);
}
