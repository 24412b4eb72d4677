// Resources of the ReSTIR passes (numbers in shared/bindings.h; src/render/restir.cpp binds
// them): the volume with its mean field and the previous frame's volume (the same resources as
// the current one for a still grid), which the target function of the temporal domain reads
// (DESIGN §4.2 step 5); the scene with the light choice and, with PLUME_HAS_SURFACES, its
// surfaces (at bindings shifted past ReSTIR's own); ReSTIR's parameters and reservoirs.
#ifndef PLUME_RESTIR_BINDINGS_GLSL
#define PLUME_RESTIR_BINDINGS_GLSL

#define PLUME_VOL_MEAN_FIELD 1
#define PLUME_VOL_PREVIOUS 1
#define PLUME_LIGHT_CHOICE 1

#include "../shared/reservoir.h"
#include "../shared/restir_types.h"
#include "../volume/bindings.glsl"
#include "../scene/bindings.glsl"
#ifdef PLUME_HAS_SURFACES
#define PLUME_SURF_BINDING_SHIFT RS_SURF_BINDING_SHIFT
#include "../surface/surfaces.glsl"
#endif

// The parameters, then the frame's pixels in the order its passes take them (render/pixel_order.h:
// packed x | y << 16; first those whose camera rays may meet the volume, then the others), then,
// with emissive surfaces, a bit per pixel (rs_lamp_pixel) and the list of the pixels whose bit is
// set (passes/restir_lamps.comp's, render/restir.cpp).
layout(std430, binding = BIND_RS_PARAMS) readonly buffer RestirParamBuffer {
  RestirParams rsParams;
  uint rsPixels[];
};
RestirParams rsp;  // a private copy (volume/bindings.glsl says why), loaded by rs_load_params()
// Every per-pixel array that grows with the image is a storage texel buffer, whose limit is
// maxTexelBufferElements texels (lavapipe: 2^27, 2 GiB of 16-byte texels), not a storage buffer
// (maxStorageBufferRange, lavapipe: 128 MiB: ReSTIR at 1920x1080 fitted none of its four largest,
// session 25). Only the accumulation, which the viewer's display reads, is a storage buffer. The
// integer formats keep every bit (the state holds counters as float bits).
// Reservoir sets: texel [set * pixels + pixel] holds RsPacked's four words.
layout(rgba32ui, binding = BIND_RS_RESERVOIRS) uniform uimageBuffer rsReservoirTexels;
// Path heads as stored: two texels per RsPathHead (its C++ layout), texels 2 * (set * pixels +
// pixel) and the next, loaded and stored whole by rs_load_head / rs_store_head (restir/bridge.glsl);
// past the RS_ALL_SETS sets' heads (RS_SETS per reservoir class, bridge.glsl), the passes' state
// between dispatches (bridge.glsl rs_state_slot).
layout(rgba32ui, binding = BIND_RS_PATHS) uniform uimageBuffer rsPathTexels;
uvec4 rs_path_word(uint i) { return imageLoad(rsPathTexels, int(i)); }
void rs_set_path_word(uint i, uvec4 v) { imageStore(rsPathTexels, int(i), v); }
// A vec4 of the passes' state (its bits as they were stored).
vec4 rs_state(uint i) { return uintBitsToFloat(imageLoad(rsPathTexels, int(i))); }
void rs_set_state(uint i, vec4 v) { imageStore(rsPathTexels, int(i), floatBitsToUint(v)); }
// Vertices 2..n of each stored path: element (set * pixels + pixel) * stride + i - 2 = (w_i, t_i), its
// bits as stored (the reconnection vertex keeps a triangle index in a float: restir_types.h). A
// storage texel buffer, or where only a storage buffer holds them, one (render/restir.cpp).
#ifdef PLUME_RS_VERTEX_BUFFER
layout(std430, binding = BIND_RS_BOUNCES) buffer BounceBuffer { uvec4 rsBounceWords[]; };
vec4 rs_bounce(uint i) { return uintBitsToFloat(rsBounceWords[i]); }
void rs_set_bounce(uint i, vec4 v) { rsBounceWords[i] = floatBitsToUint(v); }
#else
layout(rgba32ui, binding = BIND_RS_BOUNCES) uniform uimageBuffer rsBounceTexels;
vec4 rs_bounce(uint i) { return uintBitsToFloat(imageLoad(rsBounceTexels, int(i))); }
void rs_set_bounce(uint i, vec4 v) { imageStore(rsBounceTexels, int(i), floatBitsToUint(v)); }
#endif
// Progressive accumulation of final shading: [2 * pixel] = (mean rgb, n), [2 * pixel + 1] = (M2 rgb, 0).
layout(std430, binding = BIND_RS_OUTPUT) buffer OutputBuffer { vec4 rsOutput[]; };
// rsCounters[0]: reservoirs whose non-finite weights were dropped on unpack (this frame).
layout(std430, binding = BIND_RS_COUNTERS) buffer RestirCounterBuffer { uint rsCounters[]; };

layout(push_constant) uniform PushBlock { RsPush push; };

// Whether the camera rays of pixel `index` (y * width + x) may meet an emitter's front: the bits
// after the pixel list (render/pixel_order.h emitterPixelMask; with emissive surfaces only).
bool rs_lamp_pixel(uint index) { return ((rsPixels[rsp.pixelCount + (index >> 5u)] >> (index & 31u)) & 1u) != 0u; }

// The rectangle [lo, hi] of the (u, v) of the lamp pass's pixel where its camera rays may meet an
// emitter's front: the two words after the list's end for each of its pixels (render/pixel_order.h
// emitterPixelRects, rounded outwards; [0, 1]² for every pixel without RestirOptions::lampRects).
void rs_lamp_rect(out vec2 lo, out vec2 hi) {
  uint i = push.listBegin + push.listCount + 2u * gl_GlobalInvocationID.x;
  lo = unpackUnorm2x16(rsPixels[i]);
  hi = unpackUnorm2x16(rsPixels[i + 1u]);
}

// The lamp pass pixel's pieces of emitter projections (render/pixel_order.h emitterPixelTriangles;
// with RestirOptions::lampTriangles, in place of the rectangle): count pieces of 8 words from
// rsPixels[start] on: the emitter triangle's device index, the piece's weight (Le's luminance times
// its area in square pixels: rs_lamp_weight) and its three corners in the pixel's (u, v).
void rs_lamp_triangles(out uint start, out uint count) {
  uint i = push.listBegin + push.listCount + 2u * gl_GlobalInvocationID.x;
  start = rsPixels[i];
  count = rsPixels[i + 1u];
}
float rs_lamp_weight(uint start, uint j) { return uintBitsToFloat(rsPixels[start + 8u * j + 1u]); }
uint rs_lamp_piece(uint start, uint j, out vec2 a, out vec2 b, out vec2 c) {
  uint i = start + 8u * j;
  a = uintBitsToFloat(uvec2(rsPixels[i + 2u], rsPixels[i + 3u]));
  b = uintBitsToFloat(uvec2(rsPixels[i + 4u], rsPixels[i + 5u]));
  c = uintBitsToFloat(uvec2(rsPixels[i + 6u], rsPixels[i + 7u]));
  return rsPixels[i];
}

// The pixel of this invocation of a dispatch over rsPixels[push.listBegin ..][.. push.listCount]
// (one-dimensional workgroups); false past the list's end.
bool rs_dispatch_pixel(out uvec2 pixel) {
  uint i = gl_GlobalInvocationID.x;
  uint packed = i < push.listCount ? rsPixels[push.listBegin + i] : 0u;
  pixel = uvec2(packed & 0xffffu, packed >> 16u);
  return i < push.listCount;
}

// The private copies of every parameter block: first thing in every ReSTIR kernel.
void rs_load_params() {
  vol_load_params();
  scene_load_params();
  rsp = rsParams;
}

#endif
