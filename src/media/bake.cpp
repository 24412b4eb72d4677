// The bake (DESIGN §3): OpenVDB float grid -> bricks in an atlas, indirection, majorant
// hierarchy and ReSTIR's voxel mean field. See bake.h for the layout; lookups are in bake_lookup.cpp.
//
// Pipeline (every pass parallel over bricks with TBB):
//   1. core bricks: bricks whose own 8³ voxels hold a non-zero value (leaves and active tiles);
//   2. candidates: core bricks dilated by one brick (only those can see a non-zero voxel in their
//      10³ window, whose apron reaches one voxel into each neighbour);
//   3. allocate the candidates whose window holds a non-zero voxel (core bricks always do);
//   4. fill each allocated slot: texels, majorant, mean field; then the max hierarchy.
#include "media/bake.h"

#include "core/error.h"
#include "media/vdb_loader.h"

#include <openvdb/openvdb.h>

#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>

namespace plume {
namespace {

using openvdb::Coord;
using FloatTree = openvdb::FloatTree;
using LeafT = FloatTree::LeafNodeType;
using Window = std::array<float, kBrickTexelCount>;  // x fastest: [(z*10 + y)*10 + x]

constexpr float kHalfMax = 65504.0f;
constexpr float kHalfMinNormal = 0x1p-14f;

// The least float16 value >= v (v >= 0), capped at kHalfMax.
float halfAtLeast(double v) {
  if (v >= double(kHalfMax)) return kHalfMax;
  openvdb::math::half h{float(v)};  // nearest
  if (double(float(h)) < v) h.setBits(uint16_t(h.bits() + 1));
  return float(h);
}
// The lookup's float weights sum to 1 only within a few ulp, so a lookup whose 8 texels all
// equal M can return M(1 + ~10 * 2^-24). Majorants are raised by 2^-18 (64 ulp) to bound it.
constexpr float kMajorantMargin = 1.0f + 1.0f / 262144.0f;

int windowIndex(int x, int y, int z) { return (z * kBrickTexels + y) * kBrickTexels + x; }

size_t linearIndex(glm::ivec3 c, glm::ivec3 dims) {
  return (size_t(c.z) * size_t(dims.y) + size_t(c.y)) * size_t(dims.x) + size_t(c.x);
}

glm::ivec3 delinearize(size_t i, glm::ivec3 dims) {
  const size_t x = i % size_t(dims.x), yz = i / size_t(dims.x);
  return {int(x), int(yz % size_t(dims.y)), int(yz / size_t(dims.y))};
}

glm::ivec3 brickOf(const Coord& c) { return {c.x() >> 3, c.y() >> 3, c.z() >> 3}; }  // floor(c/8)

// Reads the 10³ window of brick b (voxels 8b-1 .. 8b+8) from the tree. The window overlaps
// 3³ leaf-sized blocks; each is either a leaf (read from its buffer) or uniform (a tile or the
// background, one getValue). Non-positive values (only zeros once sanitised) read as 0.
void gatherWindow(openvdb::FloatGrid::ConstAccessor& acc, glm::ivec3 b, Window& w) {
  // Along one axis, block offset d in {-1,0,1} covers window texels [lo, hi).
  static constexpr int kLo[3] = {0, 1, 9}, kHi[3] = {1, 9, 10}, kLocal0[3] = {7, 0, 0};
  for (int dz = 0; dz < 3; ++dz)
    for (int dy = 0; dy < 3; ++dy)
      for (int dx = 0; dx < 3; ++dx) {
        const Coord block(8 * (b.x + dx - 1), 8 * (b.y + dy - 1), 8 * (b.z + dz - 1));
        const LeafT* leaf = acc.probeConstLeaf(block);
        const float uniform = leaf ? 0.0f : std::max(acc.getValue(block), 0.0f);
        const float* data = leaf ? leaf->buffer().data() : nullptr;
        for (int z = kLo[dz], lz = kLocal0[dz]; z < kHi[dz]; ++z, ++lz)
          for (int y = kLo[dy], ly = kLocal0[dy]; y < kHi[dy]; ++y, ++ly)
            for (int x = kLo[dx], lx = kLocal0[dx]; x < kHi[dx]; ++x, ++lx)
              // LeafNode::coordToOffset: x slowest, z fastest.
              w[windowIndex(x, y, z)] = data ? std::max(data[(lx << 6) + (ly << 3) + lz], 0.0f) : uniform;
      }
}

bool anyPositive(const Window& w) {
  return std::any_of(w.begin(), w.end(), [](float v) { return v > 0.0f; });
}

// --- Step 1-2: core and candidate bricks ------------------------------------------------------

struct BrickBox {
  glm::ivec3 origin{0}, dims{0};
  size_t count() const { return size_t(dims.x) * size_t(dims.y) * size_t(dims.z); }
  bool contains(glm::ivec3 b) const {
    const glm::ivec3 r = b - origin;
    return r.x >= 0 && r.y >= 0 && r.z >= 0 && r.x < dims.x && r.y < dims.y && r.z < dims.z;
  }
  size_t index(glm::ivec3 b) const { return linearIndex(b - origin, dims); }
};

// Marks the bricks whose own voxels hold a positive value.
std::vector<uint8_t> coreBricks(const openvdb::FloatGrid& grid, const BrickBox& box) {
  std::vector<uint8_t> core(box.count(), 0);
  std::vector<const LeafT*> leaves;
  grid.tree().getNodes(leaves);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, leaves.size()), [&](const auto& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) {
      const float* d = leaves[i]->buffer().data();
      const glm::ivec3 b = brickOf(leaves[i]->origin());
      if (box.contains(b) && std::any_of(d, d + LeafT::SIZE, [](float v) { return v > 0.0f; }))
        core[box.index(b)] = 1;  // one leaf per brick: no races
    }
  });
  auto it = grid.tree().cbeginValueOn();
  it.setMaxDepth(FloatTree::ValueOnCIter::LEAF_DEPTH - 1);  // tiles only
  for (; it; ++it) {
    if (!(*it > 0.0f)) continue;
    const openvdb::CoordBBox tile = it.getBoundingBox();
    const glm::ivec3 lo = brickOf(tile.min()), hi = brickOf(tile.max());
    for (int z = lo.z; z <= hi.z; ++z)
      for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x)
          if (box.contains({x, y, z})) core[box.index({x, y, z})] = 1;
  }
  return core;
}

// Candidates = core dilated by one brick (26-neighbourhood), as brick-box indices in order.
std::vector<size_t> candidateBricks(const std::vector<uint8_t>& core, const BrickBox& box) {
  std::vector<uint8_t> cand(core.size(), 0);
  tbb::parallel_for(0, box.dims.z, [&](int z) {
    for (int y = 0; y < box.dims.y; ++y)
      for (int x = 0; x < box.dims.x; ++x) {
        bool any = false;
        for (int dz = -1; dz <= 1 && !any; ++dz)
          for (int dy = -1; dy <= 1 && !any; ++dy)
            for (int dx = -1; dx <= 1 && !any; ++dx) {
              const glm::ivec3 n = box.origin + glm::ivec3(x + dx, y + dy, z + dz);
              any = box.contains(n) && core[box.index(n)];
            }
        cand[linearIndex({x, y, z}, box.dims)] = any;
      }
  });
  std::vector<size_t> out;
  for (size_t i = 0; i < cand.size(); ++i)
    if (cand[i]) out.push_back(i);
  return out;
}

// --- Step 4: per-slot contents ----------------------------------------------------------------

// Quantises a texel to the storage format; returns the value a shader will read back.
float storeTexel(BakedVolume& vol, size_t texel, float v) {
  if (vol.format == TexelFormat::Float32) {
    vol.atlasF32[texel] = v;
    return v;
  }
  const openvdb::math::half h(std::min(v, kHalfMax));  // round to nearest; clamp, no Inf
  vol.atlasF16[texel] = h.bits();
  return float(h);
}

struct SlotResult {
  float majorant = 0, maxAbsError = 0, maxValue = 0;
};

// Calls put(atlas texel index, window value) for every texel of slot `slot` (the density's atlas
// and the emission channel share the layout).
template <typename Put>
void forSlotTexels(const BakedVolume& vol, uint32_t slot, const Window& w, Put&& put) {
  const glm::ivec3 o = slotTexelOrigin(vol, slot);
  for (int z = 0; z < kBrickTexels; ++z)
    for (int y = 0; y < kBrickTexels; ++y) {
      const size_t row = linearIndex(o + glm::ivec3(0, y, z), vol.atlasTexels);
      for (int x = 0; x < kBrickTexels; ++x) put(row + size_t(x), w[windowIndex(x, y, z)]);
    }
}

// Writes the window into slot `slot` of the atlas. The majorant is the max of both the float
// value and the stored value (half rounding may round up) over the texels that a lookup inside
// the brick reads: a point of [8b, 8b + 8) reads the corners floor(p) + {0, 1}, voxels 8b .. 8b + 8,
// window texels 1 .. 9 (the apron's low layer, voxel 8b - 1, belongs to the brick below). So it
// bounds the trilinear lookup of either: a convex combination of 8 of those texels never exceeds
// their max. (The whole 10³ window made the majorants looser: the bundled smoke's path tracer
// took 14% more density lookups in delta tracking and 33% more in next-event ratio tracking than
// the CPU reference, whose cells cover 9³ voxels; notes/bench/kernels.md "Session 20".)
SlotResult writeTexels(BakedVolume& vol, uint32_t slot, const Window& w) {
  SlotResult r;
  int k = 0;  // the window index of the texel put is called with (x fastest, as windowIndex)
  forSlotTexels(vol, slot, w, [&](size_t texel, float v) {
    const float s = storeTexel(vol, texel, v);
    const int x = k % kBrickTexels, y = (k / kBrickTexels) % kBrickTexels, z = k / (kBrickTexels * kBrickTexels);
    ++k;
    if (x >= 1 && y >= 1 && z >= 1) r.majorant = std::max({r.majorant, v, s});
    r.maxValue = std::max(r.maxValue, v);
    r.maxAbsError = std::max(r.maxAbsError, std::abs(s - v));
  });
  return r;
}

// ReSTIR's mean field of one brick (bake.h voxelMean, voxelResidual); returns its largest mean.
float writeMeanField(BakedVolume& vol, uint32_t slot, const Window& w) {
  float largest = 0.0f;
  float* vm = &vol.voxelMean[size_t(slot) * 512];
  float* vr = &vol.voxelResidual[size_t(slot) * 512];
  for (int z = 0; z < 8; ++z)
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x) {
        double corner[8], sum = 0.0;
        for (int k = 0; k < 8; ++k) {
          corner[k] = w[windowIndex(x + 1 + (k & 1), y + 1 + ((k >> 1) & 1), z + 1 + (k >> 2))];
          sum += corner[k];
        }
        float mean = 0.0f;
        if (sum > 0.0) mean = std::max(float(openvdb::math::half(float(std::min(sum / 8.0, double(kHalfMax))))), kHalfMinNormal);
        double dev = 0.0;
        for (double c : corner) dev = std::max(dev, std::abs(c - mean) + std::abs(c) * 0x1p-10);
        vm[(z * 8 + y) * 8 + x] = mean;
        vr[(z * 8 + y) * 8 + x] = halfAtLeast(dev);
        largest = std::max(largest, mean);
      }
  return largest;
}

// --- Layout -------------------------------------------------------------------------------------

// Slots per atlas axis: close to a cube, each axis at most maxPerAxis.
glm::ivec3 atlasLayout(uint32_t slots, int maxPerAxis, const std::string& where) {
  auto ceilDiv = [](uint64_t a, uint64_t b) { return (a + b - 1) / b; };
  const int x = std::min<int>(maxPerAxis, int(std::ceil(std::cbrt(double(slots)))));
  const uint64_t rest = ceilDiv(slots, uint64_t(x));
  const int y = std::min<int>(maxPerAxis, int(std::ceil(std::sqrt(double(rest)))));
  const uint64_t z = ceilDiv(rest, uint64_t(y));
  if (z > uint64_t(maxPerAxis))
    throw InputError(where + ": " + std::to_string(slots) + " bricks do not fit one atlas");
  return {x, y, int(z)};
}

void buildHierarchy(BakedVolume& vol, const std::vector<float>& brickMajorant) {
  vol.maxLevels.clear();
  vol.maxLevels.push_back({1, vol.brickDims, brickMajorant});
  // Coarser levels until every axis has at most kHierarchyFactor cells (at least one level).
  while (vol.maxLevels.size() == 1 ||
         glm::any(glm::greaterThan(vol.maxLevels.back().dims, glm::ivec3(kHierarchyFactor)))) {
    const MaxLevel& fine = vol.maxLevels.back();
    MaxLevel coarse;
    coarse.cellBricks = fine.cellBricks * kHierarchyFactor;
    coarse.dims = (fine.dims + kHierarchyFactor - 1) / kHierarchyFactor;
    coarse.max.assign(size_t(coarse.dims.x) * coarse.dims.y * coarse.dims.z, 0.0f);
    for (size_t i = 0; i < fine.max.size(); ++i) {
      const glm::ivec3 c = delinearize(i, fine.dims) / kHierarchyFactor;
      float& m = coarse.max[linearIndex(c, coarse.dims)];
      m = std::max(m, fine.max[i]);
    }
    vol.maxLevels.push_back(std::move(coarse));
    if (vol.maxLevels.back().dims == glm::ivec3(1)) break;
  }
}

void setTransform(BakedVolume& vol, const openvdb::FloatGrid& grid, const openvdb::CoordBBox& active) {
  // OpenVDB's Mat4 acts on row vectors (v * M, translation in row 3); glm on column vectors
  // with m[col][row]: the same numbers in the same places give the same map.
  const openvdb::Mat4d m = grid.transform().baseMap()->getAffineMap()->getMat4();
  const openvdb::Mat4d inv = m.inverse();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      vol.indexToWorld[i][j] = float(m(i, j));
      vol.worldToIndex[i][j] = float(inv(i, j));
    }
  if (active.empty()) return;
  // Trilinear support: d can be non-zero only strictly inside the active box grown by one voxel.
  vol.indexBoundsMin = glm::vec3(active.min().x(), active.min().y(), active.min().z()) - 1.0f;
  vol.indexBoundsMax = glm::vec3(active.max().x(), active.max().y(), active.max().z()) + 1.0f;
  openvdb::BBoxd world;
  for (int c = 0; c < 8; ++c) {
    const openvdb::Vec3d p((c & 1) ? vol.indexBoundsMax.x : vol.indexBoundsMin.x,
                           (c & 2) ? vol.indexBoundsMax.y : vol.indexBoundsMin.y,
                           (c & 4) ? vol.indexBoundsMax.z : vol.indexBoundsMin.z);
    world.expand(grid.transform().indexToWorld(p));
  }
  vol.worldBoundsMin = glm::vec3(world.min().x(), world.min().y(), world.min().z());
  vol.worldBoundsMax = glm::vec3(world.max().x(), world.max().y(), world.max().z());
}

// Steps 3-4 over the candidate bricks of `box`.
void fillBricks(BakedVolume& vol, const openvdb::FloatGrid& grid, const BrickBox& box,
                const std::vector<size_t>& cand, const std::vector<uint8_t>& core,
                const BakeOptions& opt, const std::string& where) {
  // Step 3: which candidates see a non-zero voxel.
  std::vector<uint8_t> alloc(cand.size(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, cand.size()), [&](const auto& r) {
    openvdb::FloatGrid::ConstAccessor acc = grid.getConstAccessor();
    Window w;
    for (size_t i = r.begin(); i != r.end(); ++i) {
      if (core[cand[i]]) { alloc[i] = 1; continue; }
      gatherWindow(acc, box.origin + delinearize(cand[i], box.dims), w);
      alloc[i] = anyPositive(w);
    }
  });
  std::vector<std::pair<size_t, uint32_t>> slots;  // (brick-box index, slot)
  for (size_t i = 0; i < cand.size(); ++i)
    if (alloc[i]) slots.emplace_back(cand[i], uint32_t(slots.size() + 1));
  vol.slotCount = uint32_t(slots.size() + 1);
  vol.atlasSlots = atlasLayout(vol.slotCount, opt.maxAtlasSlotsPerAxis, where);
  vol.atlasTexels = vol.atlasSlots * kBrickTexels;
  const size_t texels = size_t(vol.atlasTexels.x) * vol.atlasTexels.y * vol.atlasTexels.z;
  if (vol.format == TexelFormat::Float32) vol.atlasF32.assign(texels, 0.0f);
  else vol.atlasF16.assign(texels, 0);
  if (opt.meanField) {
    vol.voxelMean.assign(size_t(vol.slotCount) * 512, 0.0f);
    vol.voxelResidual.assign(size_t(vol.slotCount) * 512, 0.0f);
  }
  std::vector<float> brickMajorant(box.count(), 0.0f);
  for (const auto& [b, s] : slots) vol.indirection[b] = s;

  // Step 4: texels, majorants, coarse cells. Slots are disjoint, so writes never race.
  tbb::combinable<SlotResult> worst;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, slots.size()), [&](const auto& r) {
    openvdb::FloatGrid::ConstAccessor acc = grid.getConstAccessor();
    Window w;
    SlotResult& mine = worst.local();
    for (size_t i = r.begin(); i != r.end(); ++i) {
      const auto [b, s] = slots[i];
      gatherWindow(acc, box.origin + delinearize(b, box.dims), w);
      const SlotResult res = writeTexels(vol, s, w);
      // The majorant bounds the mean field too, whose sampling tracks against it (volume/walk.glsl
      // vol_fine_and_mean): a mean rounded to half precision may exceed its corners' largest texel
      // by up to 2^-11 of it, and a tiny one is raised to the smallest normal half.
      const float meanMax = opt.meanField ? writeMeanField(vol, s, w) : 0.0f;
      brickMajorant[b] = std::max(res.majorant, meanMax) * kMajorantMargin;
      mine.maxAbsError = std::max(mine.maxAbsError, res.maxAbsError);
      mine.maxValue = std::max(mine.maxValue, res.maxValue);
    }
  });
  worst.combine_each([&](const SlotResult& r) {
    vol.stats.maxAbsError = std::max(vol.stats.maxAbsError, r.maxAbsError);
    vol.stats.maxValue = std::max(vol.stats.maxValue, r.maxValue);
  });
  vol.stats.candidateBricks = cand.size();
  vol.stats.allocatedBricks = uint32_t(slots.size());
  buildHierarchy(vol, brickMajorant);
}

}  // namespace

const char* texelFormatName(TexelFormat format) {
  return format == TexelFormat::Float32 ? "float32" : "float16";
}

BakedVolume bakeVolume(const LoadedGrid& loaded, const BakeOptions& opt) {
  const auto start = std::chrono::steady_clock::now();
  const openvdb::FloatGrid& grid = *loaded.grid;
  const std::string where = (loaded.path.empty() ? std::string("<memory>") : loaded.path) +
                            " (grid \"" + loaded.name + "\")";
  BakedVolume vol;
  vol.format = opt.format;
  vol.stats.activeVoxels = grid.activeVoxelCount();
  const openvdb::CoordBBox active =
      vol.stats.activeVoxels ? grid.evalActiveVoxelBoundingBox() : openvdb::CoordBBox();
  setTransform(vol, grid, active);

  BrickBox box;
  if (!active.empty()) {  // active bricks plus one brick of margin (apron-only bricks)
    box.origin = brickOf(active.min()) - 1;
    box.dims = brickOf(active.max()) + 1 - box.origin + 1;
    if (double(box.dims.x) * box.dims.y * box.dims.z > double(std::numeric_limits<int32_t>::max()))
      throw InputError(where + ": active region too large for a dense brick indirection");
  }
  vol.brickOrigin = box.origin;
  vol.brickDims = box.dims;
  vol.indirection.assign(box.count(), 0);
  const std::vector<uint8_t> core = coreBricks(grid, box);
  fillBricks(vol, grid, box, candidateBricks(core, box), core, opt, where);
  vol.stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return vol;
}

void bakeEmission(BakedVolume& vol, const LoadedGrid& density, const LoadedGrid& emission) {
  const std::string where = (emission.path.empty() ? std::string("<memory>") : emission.path) + " (grid \"" +
                            emission.name + "\")";
  const openvdb::Mat4d a = density.grid->transform().baseMap()->getAffineMap()->getMat4();
  const openvdb::Mat4d b = emission.grid->transform().baseMap()->getAffineMap()->getMat4();
  double scale = 0.0, diff = 0.0;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) scale = std::max(scale, std::abs(a(i, j))), diff = std::max(diff, std::abs(a(i, j) - b(i, j)));
  if (diff > 1e-6 * scale) {
    throw InputError(where + ": its transform differs from the density grid \"" + density.name +
                     "\"'s (voxel size " + std::to_string(emission.grid->voxelSize().x()) + " vs " +
                     std::to_string(density.grid->voxelSize().x()) +
                     "); emission grids must share the density's voxels (resample it in the tool that wrote it)");
  }
  const size_t texels = size_t(vol.atlasTexels.x) * vol.atlasTexels.y * vol.atlasTexels.z;
  vol.emissionF32.assign(texels, 0.0f);
  std::vector<std::pair<size_t, uint32_t>> slots;  // (indirection index, slot)
  for (size_t i = 0; i < vol.indirection.size(); ++i)
    if (vol.indirection[i] != 0) slots.emplace_back(i, vol.indirection[i]);
  tbb::combinable<float> maxima([] { return 0.0f; });
  tbb::parallel_for(tbb::blocked_range<size_t>(0, slots.size()), [&](const auto& r) {
    openvdb::FloatGrid::ConstAccessor acc = emission.grid->getConstAccessor();
    Window w;
    float& mx = maxima.local();
    for (size_t k = r.begin(); k != r.end(); ++k) {
      const auto [i, slot] = slots[k];
      gatherWindow(acc, vol.brickOrigin + delinearize(i, vol.brickDims), w);
      forSlotTexels(vol, slot, w, [&](size_t texel, float v) {
        vol.emissionF32[texel] = v;
        mx = std::max(mx, v);
      });
    }
  });
  vol.emissionMax = maxima.combine([](float x, float y) { return std::max(x, y); });
}

std::vector<uint32_t> packedMeanField(const BakedVolume& vol) {
  std::vector<uint32_t> out(vol.voxelMean.size());
  for (size_t i = 0; i < out.size(); ++i) {  // the values are float16 already: exact conversions
    out[i] = uint32_t(openvdb::math::half(vol.voxelMean[i]).bits()) |
             uint32_t(openvdb::math::half(vol.voxelResidual[i]).bits()) << 16;
  }
  return out;
}

}  // namespace plume
