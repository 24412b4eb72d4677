// The baked volume (DESIGN §3): flat arrays ready for upload to the GPU, plus CPU lookups that
// mirror the shaders (the tests compare them against openvdb::tools::BoxSampler).
//
// Index space: voxel centres at integer coordinates; d(p) is the trilinear interpolation of the
// 8 voxels floor(p) + {0,1}³ (DESIGN §2). Brick b (integer 3-vector) owns voxels 8b .. 8b+7 and
// stores the 10³ window of voxels 8b-1 .. 8b+8 (a one-voxel apron), so a lookup at any p with
// floor(p) in brick b reads only that brick's texels. A brick is allocated iff its window holds a
// non-zero voxel; every other brick maps to slot 0 (all zeros), so d(p) = 0 there exactly.
//
// No OpenVDB types here: this header is included by GPU upload code and by tests alike.
#pragma once

#ifdef PLUME_NO_BAKE
#error "the CPU reference never uses the bake: it checks what the bake does (CMakeLists.txt)"
#endif

#include <glm/glm.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace plume {

struct LoadedGrid;  // media/vdb_loader.h

constexpr int kBrickVoxels = 8;    // voxels per brick edge
constexpr int kBrickTexels = 10;   // texels per brick edge in the atlas (8 + apron of 1 each side)
constexpr int kBrickTexelCount = kBrickTexels * kBrickTexels * kBrickTexels;
constexpr int kHierarchyFactor = 4;  // a hierarchy cell covers 4³ cells of the level below

enum class TexelFormat : uint32_t { Float32 = 0, Float16 = 1 };  // R32F or R16F atlas
const char* texelFormatName(TexelFormat format);                 // "float32", "float16"

struct BakeOptions {
  TexelFormat format = TexelFormat::Float16;
  int maxAtlasSlotsPerAxis = 204;  // 204 * 10 = 2040 texels, under a 2048 3D-image limit
  bool meanField = true;  // ReSTIR's voxel mean field (8 bytes per voxel of every brick); the path
                          // tracer does not read it, so a path-traced render leaves it out
};

// One level of the max hierarchy used for empty-space skipping (DDA). Level 0 is the per-brick
// majorant; level k cells cover kHierarchyFactor^k bricks per edge. Cell (0,0,0) of every level
// starts at brick BakedVolume::brickOrigin. Arrays are dense, x fastest: [(z*dims.y + y)*dims.x + x].
struct MaxLevel {
  int cellBricks = 1;      // bricks per cell edge
  glm::ivec3 dims{0};      // cells per axis
  std::vector<float> max;  // max of d over the cell (>= every trilinear value inside it)
};

struct BakeStats {
  double seconds = 0;            // wall time of bakeVolume
  uint64_t activeVoxels = 0;     // of the grid, tile voxels included
  uint64_t candidateBricks = 0;  // bricks whose window was inspected
  uint32_t allocatedBricks = 0;  // slots in use, slot 0 excluded
  float maxAbsError = 0;         // max |stored texel - float grid value| over all texels
  float maxValue = 0;            // max grid value (over allocated windows)
};

struct BakedVolume {
  TexelFormat format = TexelFormat::Float16;

  // Indirection: dense over the allocated bricks' bounding box (the active bricks plus one brick
  // of margin, where only apron voxels can be non-zero). Brick b maps to
  // indirection[linear(b - brickOrigin)]; a brick outside the box reads slot 0.
  glm::ivec3 brickOrigin{0};
  glm::ivec3 brickDims{0};
  std::vector<uint32_t> indirection;  // atlas slot per brick, 0 = empty

  // Atlas: slotCount slots (slot 0 = zeros) of 10³ texels, laid out as a 3D texture of
  // atlasSlots slots per axis; slot s starts at texel 10 * (s % X, (s / X) % Y, s / (X*Y)).
  // Exactly one of atlasF32 / atlasF16 (IEEE half bits) holds texels, x fastest over atlasTexels.
  uint32_t slotCount = 1;
  glm::ivec3 atlasSlots{1};
  glm::ivec3 atlasTexels{kBrickTexels};
  std::vector<float> atlasF32;
  std::vector<uint16_t> atlasF16;

  // Majorant hierarchy: levels[0] is per brick: the max over its 10³ window (of the float values
  // and of the stored texels) times (1 + 2^-18), which bounds the float rounding of a lookup.
  std::vector<MaxLevel> maxLevels;

  // ReSTIR's mean field on the GPU (volume/walk.glsl), per slot (slot 0 zeros), on single
  // voxels, stored as two float16 per voxel (packedMeanField); these are the values the GPU
  // reads: voxelMean[slot*512 + (z*8+y)*8+x] is the mean of the trilinear field over voxel
  // [v, v+1]³ (the mean of its 8 corner texels, also the field's value at the voxel's centre),
  // rounded to float16 and kept >= 2^-14 (float16's least normal, so no device flushes it to 0)
  // where a corner is positive: it is positive wherever the fine density is (candidates track
  // it: their support); voxelResidual bounds |d(p) - voxelMean| inside it: the largest corner
  // deviation from the stored mean (a trilinear field's extremes lie on the corners), widened by
  // 2^-10 of each corner to cover float16 texels and interpolation rounding, rounded up to
  // float16 (capped at 65504: beyond, residual ratio tracking stays unbiased, only noisier).
  // Both empty when baked without it (BakeOptions::meanField).
  std::vector<float> voxelMean;
  std::vector<float> voxelResidual;

  // Index -> world affine map of the grid (column vectors: world = indexToWorld * (i,j,k,1)).
  glm::mat4 indexToWorld{1.0f};
  glm::mat4 worldToIndex{1.0f};
  // Where d may be non-zero: the active index box grown by one voxel, and its world AABB.
  glm::vec3 indexBoundsMin{0.0f}, indexBoundsMax{0.0f};
  glm::vec3 worldBoundsMin{0.0f}, worldBoundsMax{0.0f};

  // The emission grid (DESIGN §2 "Emission"), baked by bakeEmission into the same slots as the
  // density: texel for texel the atlas layout, always float32 (the blackbody's Wien tail turns
  // float16's 2^-11 rounding of a temperature into ~1% of radiance at 1500 K). Where the density
  // brick is empty sigma_a is 0, so emission there cannot contribute and is not stored. Empty
  // without emission.
  std::vector<float> emissionF32;
  float emissionMax = 0;  // max stored emission texel

  BakeStats stats;
  bool empty() const { return slotCount <= 1; }
  bool hasEmission() const { return !emissionF32.empty(); }
};

struct MemoryReport {
  uint64_t atlasBytes = 0, indirectionBytes = 0, majorantBytes = 0, coarseBytes = 0;  // coarse: the mean field
  uint64_t totalBytes = 0;
  double bytesPerActiveVoxel = 0;  // total / grid active voxels (0 for an empty grid)
};

// Bakes a sanitised grid (loadFloatGrid or sanitizeGrid output), in parallel (TBB). Throws
// InputError naming the file when the grid does not fit the atlas or the dense indirection.
BakedVolume bakeVolume(const LoadedGrid& grid, const BakeOptions& options = {});

// Adds the emission channel: `emission`'s texels in every slot of `vol` (baked from the density
// grid `density`). Throws InputError naming the file and grids when the emission grid's
// transform differs from the density's (a resampling would change the field's values).
void bakeEmission(BakedVolume& vol, const LoadedGrid& density, const LoadedGrid& emission);

MemoryReport memoryReport(const BakedVolume& vol);

// --- CPU mirrors of the shader lookups (all positions in index space) ------------------------
float halfToFloat(uint16_t bits);                              // as GLSL unpackHalf2x16
uint32_t brickSlot(const BakedVolume& vol, glm::ivec3 brick);  // 0 outside the indirection box
glm::ivec3 slotTexelOrigin(const BakedVolume& vol, uint32_t slot);
float atlasTexel(const BakedVolume& vol, glm::ivec3 texel);
float sampleDensity(const BakedVolume& vol, glm::vec3 p);   // trilinear, 8 fetches, exact weights
float sampleMajorant(const BakedVolume& vol, glm::vec3 p);  // = sampleMaxLevel(vol, 0, p)
float sampleMaxLevel(const BakedVolume& vol, int level, glm::vec3 p);
float sampleVoxelMean(const BakedVolume& vol, glm::vec3 p);  // voxelMean of the voxel holding p
float sampleEmission(const BakedVolume& vol, glm::vec3 p);   // trilinear in the emission channel
// The mean field as the GPU buffer holds it: per voxel one word, the float16 mean in the low
// half and the float16 residual bound in the high half (GLSL unpackHalf2x16 .x, .y).
std::vector<uint32_t> packedMeanField(const BakedVolume& vol);

}  // namespace plume
