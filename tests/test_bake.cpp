// Bake tests (DESIGN §3): the baked lookups against openvdb::tools::BoxSampler at >= 1e5 random
// points per grid and format (brick borders, the edge of the active region, tiles), majorant and
// hierarchy bounds, conservative coarse mips, the apron allocation rule, empty grids.
#include "media/bake.h"
#include "media/vdb_loader.h"
#include "support/test_support.h"

#include <gtest/gtest.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/LevelSetSphere.h>
#include <openvdb/tools/LevelSetUtil.h>

#include <cmath>
#include <random>

namespace plume {
namespace {

using openvdb::Coord;

// Tolerances, relative to the local scale L = the largest of the 8 voxels interpolated.
// Float32: a float position p gives weights f = p - floor(p) that are exact, but 1 - f rounds
// (p in [0, 0.5)), as does f itself for p in (-1, 0): a weight is only good to 2^-25 absolute,
// so even a perfect float lookup is off by up to ~2^-25 L; the 8 products and 7 sums add
// ~11 ulp of the result. Hence |baked - exact| <= 1e-6 L, and against BoxSampler (whose nested
// lerps are themselves within 1e-6 L of exact) <= 2e-6 L by the triangle inequality.
constexpr double kF32Rel = 1e-6;
// Float16 round-to-nearest: |q(v) - v| <= 2^-11 |v| for normal halves, <= 2^-25 for subnormals,
// hence |d_half - d| <= 2^-11 d + 2^-25 (weights are a partition of unity), plus the float terms.
const double kF16Rel = std::ldexp(1.0, -11), kF16Abs = std::ldexp(1.0, -25);

LoadedGrid wrap(openvdb::FloatGrid::Ptr g) {
  initOpenVdb();
  LoadedGrid l;
  l.grid = g;
  l.name = "density";
  l.replacedValues = sanitizeGrid(*g);
  return l;
}

// Smooth noise thresholded into sparse blobs, with tiny values at every blob's edge, isolated
// specks (one 1e-7, one below half precision), an 8³ active tile and a negative voxel (sanitised).
openvdb::FloatGrid::Ptr makeNoisyGrid() {
  auto g = openvdb::FloatGrid::create(0);
  auto acc = g->getAccessor();
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> phase(0.0f, 6.2831853f);
  float ph[6];
  for (float& p : ph) p = phase(rng);
  for (int z = -20; z < 60; ++z)
    for (int y = -13; y < 50; ++y)
      for (int x = -30; x < 45; ++x) {
        const float n = std::sin(0.21f * x + ph[0]) * std::sin(0.17f * y + ph[1]) * std::sin(0.23f * z + ph[2]) +
                        0.5f * std::sin(0.53f * x + 0.31f * z + ph[3]) * std::sin(0.47f * y + ph[4]);
        const float v = n - 0.45f;
        if (v > 0.0f) acc.setValue(Coord(x, y, z), v * (1.0f + 0.3f * std::sin(1.3f * x + ph[5])));
      }
  acc.setValue(Coord(-60, 7, 3), 1e-7f);
  acc.setValue(Coord(-70, 9, 5), 1e-30f);
  acc.setValue(Coord(-50, 0, 0), -1.0f);
  g->tree().addTile(1, Coord(80, 0, 0), 0.6f, true);
  return g;
}

openvdb::FloatGrid::Ptr makeFogSphere() {
  auto g = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(24.0f, openvdb::Vec3f(3, -2, 5), 1.0f, 3.0f);
  openvdb::tools::sdfToFogVolume(*g);
  g->setTransform(openvdb::math::Transform::createLinearTransform(0.1));
  return g;
}

// Exact trilinear interpolation in double of the grid's (float) values.
double exactTrilinear(const openvdb::FloatGrid::ConstAccessor& acc, glm::vec3 p) {
  const glm::dvec3 fl = glm::floor(glm::dvec3(p)), f = glm::dvec3(p) - fl;
  double sum = 0;
  for (int c = 0; c < 8; ++c) {
    const int ox = c & 1, oy = (c >> 1) & 1, oz = (c >> 2) & 1;
    const double w = (ox ? f.x : 1 - f.x) * (oy ? f.y : 1 - f.y) * (oz ? f.z : 1 - f.z);
    sum += w * acc.getValue(Coord(int(fl.x) + ox, int(fl.y) + oy, int(fl.z) + oz));
  }
  return sum;
}

float localMax(const openvdb::FloatGrid::ConstAccessor& acc, glm::vec3 p) {
  const glm::ivec3 v(glm::floor(p));
  float m = 0;
  for (int c = 0; c < 8; ++c) m = std::max(m, acc.getValue(Coord(v.x + (c & 1), v.y + ((c >> 1) & 1), v.z + ((c >> 2) & 1))));
  return m;
}

// Test points: uniform over the active box grown by 3 voxels; on brick borders (coordinates at,
// just below and just above multiples of 8, and on the apron voxel 8k-1); near the edge of the
// positive region (a positive voxel with a zero neighbour, +-1.5 voxels); around active tiles.
std::vector<glm::vec3> testPoints(const openvdb::FloatGrid& grid, size_t perKind, uint32_t seed) {
  std::mt19937 rng(seed);
  const openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
  const glm::vec3 lo(box.min().x() - 3, box.min().y() - 3, box.min().z() - 3);
  const glm::vec3 hi(box.max().x() + 3, box.max().y() + 3, box.max().z() + 3);
  auto uni = [&](float a, float b) { return std::uniform_real_distribution<float>(a, b)(rng); };
  auto inBox = [&] { return glm::vec3(uni(lo.x, hi.x), uni(lo.y, hi.y), uni(lo.z, hi.z)); };
  std::vector<glm::vec3> pts;
  for (size_t i = 0; i < perKind; ++i) pts.push_back(inBox());
  const float borderOffsets[] = {0.0f, -1e-4f, 1e-4f, -1.0f, -0.5f, 0.5f, 7.9999f, -0.9999f};
  for (size_t i = 0; i < perKind; ++i) {
    glm::vec3 p = inBox();
    for (int a = 0; a < 3; ++a)
      if (rng() % 3 != 0) p[a] = 8.0f * std::floor(p[a] / 8.0f) + borderOffsets[rng() % 8];
    pts.push_back(p);
  }
  std::vector<glm::vec3> edge;  // positive voxels with a zero face neighbour
  auto acc = grid.getConstAccessor();
  for (auto it = grid.cbeginValueOn(); it; ++it) {
    if (!(*it > 0) || !it.isVoxelValue()) continue;
    const Coord c = it.getCoord();
    for (int a = 0; a < 6; ++a) {
      Coord n = c;
      n[a / 2] += (a & 1) ? 1 : -1;
      if (acc.getValue(n) == 0) { edge.push_back(glm::vec3(c.x(), c.y(), c.z())); break; }
    }
  }
  for (size_t i = 0; i < perKind && !edge.empty(); ++i)
    pts.push_back(edge[rng() % edge.size()] + glm::vec3(uni(-1.5f, 1.5f), uni(-1.5f, 1.5f), uni(-1.5f, 1.5f)));
  std::vector<glm::vec3> tiles;  // tile boxes grown by 2 voxels
  auto it = grid.cbeginValueOn();
  it.setMaxDepth(openvdb::FloatTree::ValueOnCIter::LEAF_DEPTH - 1);
  for (; it; ++it) tiles.push_back(glm::vec3(it.getCoord().x(), it.getCoord().y(), it.getCoord().z()));
  for (size_t i = 0; i < perKind; ++i)  // without tiles: more edge points instead
    pts.push_back(tiles.empty() ? edge[rng() % edge.size()] + glm::vec3(uni(-1.5f, 1.5f), uni(-1.5f, 1.5f), uni(-1.5f, 1.5f))
                                : tiles[rng() % tiles.size()] + glm::vec3(uni(-2, 10), uni(-2, 10), uni(-2, 10)));
  return pts;
}

struct CheckCounts {
  size_t points = 0, positive = 0, tinyPositive = 0, failures = 0;
};

// Every property of one point; returns false (after recording failures) if any does not hold.
bool checkPoint(const BakedVolume& vol, const openvdb::FloatGrid& grid,
                const openvdb::FloatGrid::ConstAccessor& acc, glm::vec3 p, std::string& why) {
  const float box = openvdb::tools::BoxSampler::sample(grid.tree(), openvdb::Vec3R(p.x, p.y, p.z));
  const double exact = exactTrilinear(acc, p);
  const double lmax = localMax(acc, p);
  const float d = sampleDensity(vol, p);
  const bool f32 = vol.format == TexelFormat::Float32;
  const double tolExact = kF32Rel * lmax + (f32 ? 0.0 : kF16Rel * exact + kF16Abs);
  const double tolBox = tolExact + kF32Rel * lmax;
  const float maj = sampleMajorant(vol, p);
  char buf[400];
  std::snprintf(buf, sizeof buf, "p=(%.7g %.7g %.7g) baked=%.9g box=%.9g exact=%.9g majorant=%.9g mean=%.9g",
                p.x, p.y, p.z, d, box, exact, maj, sampleVoxelMean(vol, p));
  why = buf;
  if (std::abs(d - exact) > tolExact) return why += " [vs exact]", false;
  if (std::abs(d - box) > tolBox) return why += " [vs BoxSampler]", false;
  if (maj < d || maj < box) return why += " [majorant]", false;
  for (int l = 1; l < int(vol.maxLevels.size()); ++l)
    if (sampleMaxLevel(vol, l, p) < sampleMaxLevel(vol, l - 1, p)) return why += " [hierarchy]", false;
  if ((d > 0 || box > 0) && !(sampleVoxelMean(vol, p) > 0)) return why += " [mean field misses density]", false;
  return true;
}

CheckCounts checkBake(const BakedVolume& vol, const openvdb::FloatGrid& grid, const std::vector<glm::vec3>& pts) {
  CheckCounts n;
  const auto acc = grid.getConstAccessor();
  const float gridMax = vol.stats.maxValue;
  for (const glm::vec3& p : pts) {
    std::string why;
    ++n.points;
    if (!checkPoint(vol, grid, acc, p, why) && ++n.failures <= 10) ADD_FAILURE() << texelFormatName(vol.format) << ": " << why;
    const double e = exactTrilinear(acc, p);
    n.positive += e > 0;
    n.tinyPositive += e > 0 && e < 1e-3 * gridMax;
  }
  EXPECT_EQ(n.failures, 0u) << "of " << n.points << " points";
  return n;
}

void checkGrid(const openvdb::FloatGrid::Ptr& g, size_t perKind, size_t minPoints) {
  const LoadedGrid l = wrap(g);
  const auto pts = testPoints(*g, perKind, 11);
  ASSERT_GE(pts.size(), minPoints);
  for (TexelFormat f : {TexelFormat::Float32, TexelFormat::Float16}) {
    BakeOptions opt;
    opt.format = f;
    const BakedVolume vol = bakeVolume(l, opt);
    EXPECT_GT(vol.stats.allocatedBricks, 0u);
    if (f == TexelFormat::Float32) EXPECT_EQ(vol.stats.maxAbsError, 0.0f);
    else EXPECT_LE(vol.stats.maxAbsError, kF16Rel * vol.stats.maxValue);
    const CheckCounts n = checkBake(vol, *g, pts);
    EXPECT_GT(n.positive, pts.size() / 10);
    EXPECT_GT(n.tinyPositive, 100u) << "too few points where the fine density is tiny but positive";
    const MemoryReport m = memoryReport(vol);
    std::printf("[ %s ] %zu points (%zu positive, %zu tiny); %u bricks, %.2f bytes/active voxel, "
                "max |stored-float| %.3g, %.3g active voxels/s\n",
                texelFormatName(f), n.points, n.positive, n.tinyPositive, vol.stats.allocatedBricks,
                m.bytesPerActiveVoxel, vol.stats.maxAbsError, vol.stats.activeVoxels / vol.stats.seconds);
  }
}

TEST(Bake, NoisyGridMatchesBoxSamplerWithConservativeBounds) {
  checkGrid(makeNoisyGrid(), 30000, 100000);
}

TEST(Bake, FogSphereWithTilesMatchesBoxSampler) {
  auto g = makeFogSphere();
  ASSERT_GT(g->tree().activeTileCount(), 0u);
  checkGrid(g, 30000, 100000);
  const BakedVolume vol = bakeVolume(wrap(g));
  EXPECT_EQ(sampleDensity(vol, glm::vec3(3.3f, -2.1f, 5.6f)), 1.0f);  // deep inside: tiles
}

TEST(Bake, BlenderSmokeMatchesBoxSampler) {
  const std::string shared = test::sharedVolumesPath();
  if (shared.empty()) GTEST_SKIP() << test::sharedVolumesMissing();
  const LoadedGrid l = loadFloatGrid(shared + "/smoke/smoke_0012.vdb", "density");
  checkGrid(l.grid, 30000, 100000);
}

// The apron rule: one voxel at (8,8,8) is the first voxel of brick (1,1,1) and the apron of the
// seven bricks below it; all eight must be allocated or lookups in [7,8)³ would read 0.
TEST(Bake, BricksSeeingOnlyANeighboursVoxelAreAllocated) {
  auto g = openvdb::FloatGrid::create(0);
  g->tree().setValue(Coord(8, 8, 8), 1.0f);
  const BakedVolume vol = bakeVolume(wrap(g), {TexelFormat::Float32});
  EXPECT_EQ(vol.stats.allocatedBricks, 8u);
  for (int c = 0; c < 8; ++c) EXPECT_NE(brickSlot(vol, glm::ivec3(c & 1, (c >> 1) & 1, (c >> 2) & 1)), 0u);
  EXPECT_EQ(brickSlot(vol, glm::ivec3(2, 1, 1)), 0u);
  EXPECT_FLOAT_EQ(sampleDensity(vol, glm::vec3(7.5f)), 0.125f);
  EXPECT_FLOAT_EQ(sampleDensity(vol, glm::vec3(8.5f)), 0.125f);
  EXPECT_EQ(sampleDensity(vol, glm::vec3(8.0f)), 1.0f);
  EXPECT_EQ(sampleDensity(vol, glm::vec3(9.0f, 8.0f, 8.0f)), 0.0f);
  EXPECT_NEAR(sampleMajorant(vol, glm::vec3(7.5f)), 1.0f, 1e-5);  // 1 plus the rounding margin
  EXPECT_GE(sampleMajorant(vol, glm::vec3(7.5f)), 1.0f);
  EXPECT_FLOAT_EQ(sampleVoxelMean(vol, glm::vec3(7.01f)), 0.125f);  // voxel (7,7,7): one corner of 8 is 1
  EXPECT_EQ(sampleVoxelMean(vol, glm::vec3(6.5f)), 0.0f);           // voxel (6,6,6) sees nothing
}

TEST(Bake, EmptyGridBakesToNothing) {
  for (const bool activeZero : {false, true}) {
    auto g = openvdb::FloatGrid::create(0);
    if (activeZero) g->tree().setValue(Coord(3, 4, 5), 0.0f);  // an active voxel whose value is 0
    const BakedVolume vol = bakeVolume(wrap(g));
    EXPECT_EQ(vol.stats.allocatedBricks, 0u);
    EXPECT_TRUE(vol.empty());
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-50, 50);
    for (int i = 0; i < 1000; ++i) {
      const glm::vec3 p(u(rng), u(rng), u(rng));
      EXPECT_EQ(sampleDensity(vol, p), 0.0f);
      EXPECT_EQ(sampleMajorant(vol, p), 0.0f);
      EXPECT_EQ(sampleVoxelMean(vol, p), 0.0f);
      EXPECT_EQ(sampleMaxLevel(vol, 1, p), 0.0f);
    }
  }
  const BakedVolume none = bakeVolume(wrap(openvdb::FloatGrid::create(0)));
  EXPECT_TRUE(none.indirection.empty());
  EXPECT_EQ(memoryReport(none).bytesPerActiveVoxel, 0.0);
}

TEST(Bake, TransformAndBoundsFollowTheGrid) {
  auto g = openvdb::FloatGrid::create(0);
  g->tree().setValue(Coord(-4, 2, 10), 1.0f);
  g->tree().setValue(Coord(20, 30, 11), 1.0f);
  auto xf = openvdb::math::Transform::createLinearTransform(0.5);
  xf->postRotate(0.3, openvdb::math::Y_AXIS);
  xf->postTranslate(openvdb::Vec3d(1, -2, 3));
  g->setTransform(xf);
  const BakedVolume vol = bakeVolume(wrap(g));
  for (const glm::vec3 p : {glm::vec3(0), glm::vec3(-4, 2, 10), glm::vec3(20.5f, 30.25f, 11)}) {
    const openvdb::Vec3d w = xf->indexToWorld(openvdb::Vec3d(p.x, p.y, p.z));
    const glm::vec4 wb = vol.indexToWorld * glm::vec4(p, 1.0f);
    const glm::vec4 back = vol.worldToIndex * wb;
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(wb[a], w[a], 1e-5);
      EXPECT_NEAR(back[a], p[a], 1e-4);
    }
  }
  EXPECT_EQ(vol.indexBoundsMin, glm::vec3(-5, 1, 9));
  EXPECT_EQ(vol.indexBoundsMax, glm::vec3(21, 31, 12));
  const openvdb::Vec3d c = xf->indexToWorld(openvdb::Vec3d(21, 31, 12));
  for (int a = 0; a < 3; ++a) {
    EXPECT_LE(vol.worldBoundsMin[a], c[a] + 1e-5);
    EXPECT_GE(vol.worldBoundsMax[a], c[a] - 1e-5);
  }
}

TEST(Bake, HalfDecodeMatchesOpenVdbHalf) {
  for (uint32_t bits = 0; bits < 0x10000u; ++bits) {
    openvdb::math::half h;
    h.setBits(uint16_t(bits));
    const float ref = float(h), got = halfToFloat(uint16_t(bits));
    if (std::isnan(ref)) EXPECT_TRUE(std::isnan(got));
    else ASSERT_EQ(got, ref) << bits;
  }
}

TEST(Bake, AtlasLayoutHoldsEverySlot) {
  const BakedVolume vol = bakeVolume(wrap(makeNoisyGrid()), {TexelFormat::Float16});
  const glm::ivec3 s = vol.atlasSlots;
  EXPECT_GE(uint64_t(s.x) * s.y * s.z, vol.slotCount);
  EXPECT_EQ(vol.atlasTexels, s * kBrickTexels);
  EXPECT_EQ(vol.atlasF16.size(), size_t(vol.atlasTexels.x) * vol.atlasTexels.y * vol.atlasTexels.z);
  EXPECT_TRUE(vol.atlasF32.empty());
  EXPECT_EQ(vol.voxelMean.size(), size_t(vol.slotCount) * 512);
  for (int i = 0; i < kBrickTexelCount; ++i) EXPECT_EQ(vol.atlasF16[size_t(i % 10 + (i / 10 % 10) * vol.atlasTexels.x + (i / 100) * vol.atlasTexels.x * vol.atlasTexels.y)], 0);
  const glm::ivec3 last = slotTexelOrigin(vol, vol.slotCount - 1);
  EXPECT_TRUE(glm::all(glm::lessThanEqual(last + kBrickTexels, vol.atlasTexels)));
}

// A bake without ReSTIR's mean field (path tracing) holds the same texels and no memory for the
// field; with it a brick's majorant also bounds its voxels' means (ReSTIR's candidates track the
// mean field against it), so it is raised only in bricks where a mean, rounded to half precision,
// exceeded the texels' majorant (by at most the rounding: 2^-11 of it), or a tiny one was raised to
// the smallest normal half.
TEST(Bake, WithoutTheMeanFieldTheRestIsTheSame) {
  BakeOptions without;
  without.meanField = false;
  const BakedVolume a = bakeVolume(wrap(makeNoisyGrid()));
  const BakedVolume b = bakeVolume(wrap(makeNoisyGrid()), without);
  EXPECT_FALSE(a.voxelMean.empty());
  EXPECT_TRUE(b.voxelMean.empty() && b.voxelResidual.empty());
  EXPECT_EQ(a.atlasF16, b.atlasF16);
  EXPECT_EQ(a.indirection, b.indirection);
  ASSERT_EQ(a.maxLevels.size(), b.maxLevels.size());
  const std::vector<float>& ma0 = a.maxLevels[0].max;
  const std::vector<float>& mb0 = b.maxLevels[0].max;
  ASSERT_EQ(ma0.size(), mb0.size());
  ASSERT_EQ(ma0.size(), a.indirection.size());
  int raised = 0;
  for (size_t i = 0; i < ma0.size(); ++i) {
    const uint32_t slot = a.indirection[i];
    float meanMax = 0.0f;
    for (int v = 0; slot != 0 && v < 512; ++v) meanMax = std::max(meanMax, a.voxelMean[size_t(slot) * 512 + v]);
    EXPECT_GE(ma0[i], meanMax) << "brick " << i;
    EXPECT_GE(ma0[i], mb0[i]) << "brick " << i;
    if (ma0[i] != mb0[i]) {
      ++raised;
      // (a positive mean is at least the smallest normal half, 2^-14)
      EXPECT_LE(ma0[i], std::max(mb0[i] * (1.0f + 0x1p-10f), 0x1p-14f * (1.0f + 0x1p-17f))) << "brick " << i;
    }
  }
  std::printf("[bake] %d of %zu majorants raised to the bricks' largest means\n", raised, ma0.size());
  // The coarser levels (maxima of the finer ones) are no lower than without the field either.
  for (size_t k = 1; k < a.maxLevels.size(); ++k)
    for (size_t i = 0; i < a.maxLevels[k].max.size(); ++i) EXPECT_GE(a.maxLevels[k].max[i], b.maxLevels[k].max[i]) << k;
  const MemoryReport ma = memoryReport(a), mb = memoryReport(b);
  EXPECT_EQ(mb.coarseBytes, 0u);
  EXPECT_EQ(ma.totalBytes - ma.coarseBytes, mb.totalBytes);
  EXPECT_EQ(ma.coarseBytes, uint64_t(a.slotCount) * 512 * 4);  // two float16 per voxel
  EXPECT_EQ(packedMeanField(a).size(), size_t(a.slotCount) * 512);
}

// ReSTIR's mean field (bake.h voxelMean, voxelResidual): the mean of a trilinear field over a
// voxel is its value at the voxel's centre (multilinear, symmetric interval); the residual bound
// holds at random points and is tight (the largest deviation found comes within 40% of it: the
// extremes lie on the corners, which random points only approach); and the mean is positive
// wherever the fine density is (candidates track the mean field: this is their coverage of the
// target's support).
TEST(Bake, VoxelMeanAndResidualBoundDescribeTheTrilinearFieldAndCoverItsSupport) {
  for (const TexelFormat format : {TexelFormat::Float32, TexelFormat::Float16}) {
    BakeOptions options;
    options.format = format;
    const BakedVolume vol = bakeVolume(wrap(makeNoisyGrid()), options);
    ASSERT_EQ(vol.voxelMean.size(), size_t(vol.slotCount) * 512);
    ASSERT_EQ(vol.voxelResidual.size(), size_t(vol.slotCount) * 512);
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    int cells = 0, tight = 0, positive = 0;
    for (int bz = 0; bz < vol.brickDims.z; ++bz)
      for (int by = 0; by < vol.brickDims.y; ++by)
        for (int bx = 0; bx < vol.brickDims.x; ++bx) {
          const glm::ivec3 brick = vol.brickOrigin + glm::ivec3(bx, by, bz);
          const uint32_t slot = brickSlot(vol, brick);
          if (slot == 0) continue;
          for (int c = 0; c < 512; ++c) {
            const glm::ivec3 cell(c % 8, (c / 8) % 8, c / 64);
            const glm::vec3 lo = glm::vec3(brick * kBrickVoxels + cell);
            const double mean = vol.voxelMean[size_t(slot) * 512 + size_t(c)];
            const double bound = vol.voxelResidual[size_t(slot) * 512 + size_t(c)];
            const double centre = sampleDensity(vol, lo + 0.5f);
            // What the GPU reads: float16 values (exact round trip), no subnormal mean.
            ASSERT_EQ(double(float(openvdb::math::half(float(mean)))), mean);
            ASSERT_EQ(double(float(openvdb::math::half(float(bound)))), bound);
            ASSERT_TRUE(mean == 0.0 || mean >= 0x1p-14) << mean;
            // Exact but for storage and float arithmetic: the mean is stored as float16 (2^-11
            // relative rounding, and at least 2^-14 where a corner is positive), the centre
            // lookup reads the stored texels (float16: 2^-11 relative rounding of each corner)
            // with float trilinear weights; every corner is <= mean + bound.
            const double tol = 0x1p-10 * (mean + bound) + (mean == 0x1p-14 ? 0x1p-14 : 0.0);
            ASSERT_NEAR(mean, centre, tol) << "brick " << bx << "," << by << "," << bz << " voxel " << c;
            double worst = 0;
            for (int k = 0; k < 32; ++k) {
              const double d = sampleDensity(vol, lo + glm::vec3(u(rng), u(rng), u(rng)));
              worst = std::max(worst, std::abs(d - mean));
              if (d > 0) {
                ASSERT_GT(mean, 0.0) << "brick " << bx << "," << by << "," << bz << " voxel " << c;
              }
            }
            ASSERT_LE(worst, bound) << "brick " << bx << "," << by << "," << bz << " voxel " << c;
            if (bound > 0) ++cells, tight += worst > 0.6 * bound;
            positive += mean > 0;
          }
        }
    EXPECT_GT(cells, 5000);
    EXPECT_GT(positive, 1000);
    EXPECT_GT(tight, cells / 2) << "the bound is loose in most voxels";
  }
}

}  // namespace
}  // namespace plume
