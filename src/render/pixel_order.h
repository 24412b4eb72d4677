// Which pixels' camera rays may meet a volume (render/restir.cpp orders its passes' pixels by it).
// On a SIMD back end such as lavapipe a pixel whose rays miss the volume still costs its subgroup
// masked passes of every walk its kernels hold (docs/architecture.md "Call sites, not calls, cost
// time"): ReSTIR runs its walking kernels over the pixels that may meet the volume and walk-free
// variants over the others (notes/restir.md "Session 24").
#pragma once

#include "shaders/shared/gpu_types.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace plume {

// A frame's pixels, packed x | y << 16: first the `inside` ones, whose camera rays may meet the
// volume's box at some sub-pixel position, then the others, whose every ray misses it; each part
// in tile order (kPixelOrderTile² tiles row-major, each tile row-major), so that a workgroup of
// 64 list entries covers an 8 x 8 tile where the tile is whole (its rays share cache lines: a
// 64 x 1 strip made the Blender smoke's final shading ~20% slower) and its subgroups of 8 a row.
constexpr int kPixelOrderTile = 8;
struct PixelOrder {
  std::vector<uint32_t> pixels;
  uint32_t inside = 0;
};

// An index-space box.
struct IndexBox {
  glm::vec3 lo{0.0f}, hi{0.0f};
};

// Where a volume's density may be non-zero, in index space: inside `bounds` (GpuVolume
// boundsMin/Max) and, where `cells` is not empty, inside one of them (the cells of one level of
// the majorant hierarchy whose majorant is not 0: render/gpu_volume.cpp).
struct VolumeFootprint {
  IndexBox bounds;
  std::vector<IndexBox> cells;
  glm::mat4 indexToWorld{1.0f};
  bool empty = false;
};

// The pixels of a width x height image seen by the pinhole camera `cam` (shared::cam_direction)
// whose rays may meet the footprint. Conservative: every box is grown by kPixelOrderBoxMargin
// index units and its projection by kPixelOrderPixelMargin pixels, far above any rounding of the
// rays on a device; the bounds' projection is their hull, a cell's its bounding rectangle; a box
// that reaches the camera's plane makes every pixel inside (one wholly behind it none); an empty
// volume has none inside.
constexpr float kPixelOrderBoxMargin = 0.05f;
constexpr double kPixelOrderPixelMargin = 1.0;
PixelOrder volumePixelOrder(const shared::GpuCamera& cam, int width, int height, const VolumeFootprint& volume);

// Every pixel, in tile order, all inside.
PixelOrder allPixels(int width, int height);

// Where the camera rays of a width x height image seen by the pinhole camera `cam` may meet the
// front of an emissive triangle (`vertices`: three world-space corners per triangle; the front is
// the side its corners' counter-clockwise normal points to, where surf_emitted emits): per pixel
// (y * width + x), the rectangle of its square, in its own (u, v) in [0, 1]² (u right, v down, as
// restir/bridge.glsl's domains), rounded outwards to 16-bit fixed point and packed as
// packUnorm2x16 would, (u0, v0) in the low word and (u1, v1) in the high word; kNoEmitterRect
// where no triangle may be seen (ReSTIR's lamp reservoir traces its camera rays in those pixels
// only, and in each only in its rectangle: restir/candidates.glsl). Conservative: a triangle is
// left out only when the camera is behind its plane or it lies wholly behind the camera's plane;
// the rest contribute the bounding rectangle of their projection (clipped to the front of the
// camera's plane) grown by kEmitterPixelMargin pixels (a device's rounding of a camera ray is
// below 10^-5 pixels at 8192 pixels across; a lamp smaller than a pixel should mark one or two
// pixels in each direction, not three), a pixel's rectangle the union of their parts inside it.
constexpr double kEmitterPixelMargin = 1.0 / 16.0;
constexpr uint64_t kNoEmitterRect = 0xffffu | uint64_t(0xffffu) << 16;  // u0 = v0 = 1 > u1 = v1 = 0
constexpr uint64_t kWholePixelRect = uint64_t(0xffffffffu) << 32;      // [0, 1]²
std::vector<uint64_t> emitterPixelRects(const shared::GpuCamera& cam, int width, int height,
                                        const std::vector<glm::vec3>& vertices);

// Where ReSTIR's lamp reservoir draws its camera rays (restir/candidates.glsl
// rs_lamp_triangle_candidates): for each pixel, each emitter triangle that its grown rectangle
// above meets contributes the region of the pixel's (u, v) that its projection covers, with every
// edge moved out by kEmitterRegionGrowth pixels (far above the rounding of the projection and of a
// device's camera rays, so the region holds every (u, v) whose ray meets the triangle; the whole
// pixel where the camera's plane cuts the triangle), cut to the pixel's square and split into a fan
// of triangles, the pieces. Pixel i's pieces are pieces[begin[i] .. begin[i + 1]), by increasing
// triangle index (into `vertices` / 3). Every triangle in every pixel, each on the whole of it,
// where a projection is not a number.
constexpr double kEmitterRegionGrowth = 1.0 / 1024.0;
struct EmitterPiece {
  uint32_t triangle = 0;  // index into `vertices` / 3
  float area = 0.0f;      // in square pixels (> 0)
  glm::vec2 a, b, c;      // corners, in the pixel's (u, v)
};
struct EmitterPixelLists {
  std::vector<uint32_t> begin;  // width * height + 1 offsets
  std::vector<EmitterPiece> pieces;
};
EmitterPixelLists emitterPixelTriangles(const shared::GpuCamera& cam, int width, int height,
                                        const std::vector<glm::vec3>& vertices);

// The area of the convex polygon `corners` (pixel units, x right, y down) inside pixel (x, y)'s square.
double polygonAreaInPixel(const std::vector<glm::dvec2>& corners, int x, int y);

// The pixels that have a rectangle: bit i % 32 of word i / 32 for pixel i = y * width + x.
std::vector<uint32_t> emitterPixelMask(const std::vector<uint64_t>& rects);

inline uint32_t packPixel(uint32_t x, uint32_t y) { return x | y << 16; }

}  // namespace plume
