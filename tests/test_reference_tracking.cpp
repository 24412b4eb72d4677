// Tier b (DESIGN §7): the reference's tracking estimators on analytic media. Ratio tracking and
// delta tracking must average to exp(-tau) within 4 standard errors; the reference's own
// majorant grid must bound the trilinear density everywhere.
#include "media/vdb_loader.h"
#include "reference/medium.h"
#include "support/grids.h"

#include <glm/glm.hpp>
#include <gtest/gtest.h>
#include <openvdb/tools/LevelSetSphere.h>
#include <openvdb/tools/LevelSetUtil.h>

#include <cmath>

using namespace plume;
using namespace plume::ref;
using glm::dvec3;

namespace {

struct Estimate {
  double mean, stdErr;
};

template <class F>
Estimate average(int n, F&& sample) {
  double sum = 0, sumSq = 0;
  for (int i = 0; i < n; ++i) {
    double x = sample();
    sum += x;
    sumSq += x * x;
  }
  double mean = sum / n;
  double var = std::max(0.0, sumSq / n - mean * mean) * n / (n - 1);
  return {mean, std::sqrt(var / n)};
}

void expectTransmittance(const ReferenceMedium& m, const Ray& ray, double tMax, double tau, uint64_t seed) {
  const double expected = std::exp(-tau);
  auto acc = m.accessor();
  TrackingStats stats;
  Pcg32 rng(seed, 1);
  const int n = 1000000;
  Estimate ratio = average(n, [&] { return m.ratioTracking(ray, tMax, rng, acc, stats); });
  Estimate delta = average(n, [&] {
    double t;
    return m.sampleCollision(ray, tMax, rng, acc, t, stats) ? 0.0 : 1.0;
  });
  EXPECT_NEAR(ratio.mean, expected, 4 * ratio.stdErr + 1e-12) << "ratio tracking, tau=" << tau;
  EXPECT_NEAR(delta.mean, expected, 4 * delta.stdErr + 1e-12) << "delta tracking, tau=" << tau;
  // The test must be able to see a 2% error in the transmittance.
  EXPECT_LT(4 * ratio.stdErr, 0.02 * expected);
  EXPECT_LT(4 * delta.stdErr, 0.02 * expected);
  EXPECT_EQ(stats.truncated.load(), 0u);
}

}  // namespace

TEST(ReferenceTracking, ConstantSlabMatchesBeerLambert) {
  const int n = 64;
  const double vs = 1.0 / 32;  // index [0,63] -> world [0, 1.97]
  auto grid = test::makeBoxGrid(n, vs);
  for (double scale : {0.5, 2.0}) {
    ReferenceMedium m(grid, float(scale));
    // Along +x through the constant interior, from world x = 0.2 to 1.7.
    Ray ray{dvec3(0.2, 1.0, 1.0), dvec3(1, 0, 0)};
    expectTransmittance(m, ray, 1.5, scale * 1.5, 11);
    // Oblique ray, still inside the constant region.
    dvec3 d = glm::normalize(dvec3(1, 0.5, -0.3));
    expectTransmittance(m, {dvec3(0.3, 0.5, 1.5), d}, 1.0, scale * 1.0, 12);
  }
}

TEST(ReferenceTracking, LinearRampMatchesAnalyticOpticalDepth) {
  const int n = 64;
  const double vs = 1.0 / 32, scale = 3.0;
  auto grid = test::makeRampGrid(n, vs);
  ReferenceMedium m(grid, float(scale));
  // d(x) = x_index / 63; along a ray x_index(t) = x0 + t * dx / vs.
  dvec3 o(0.1, 1.0, 1.0), d = glm::normalize(dvec3(1, 0.2, 0.1));
  const double L = 1.6, x0 = o.x / vs, k = d.x / vs;
  const double tau = scale / (n - 1) * (x0 * L + 0.5 * k * L * L);
  expectTransmittance(m, {o, d}, L, tau, 21);
}

TEST(ReferenceTracking, AffineTransformsAreHonoured) {
  // A rotated, scaled and translated slab: tau depends only on the world length inside it.
  auto grid = test::makeBoxGrid(48, 1.0);
  auto xform = openvdb::math::Transform::createLinearTransform(0.05);
  xform->postRotate(0.5, openvdb::math::Z_AXIS);
  xform->postTranslate(openvdb::Vec3d(3, -1, 2));
  grid->setTransform(xform);
  const double scale = 1.2;
  ReferenceMedium m(grid, float(scale));
  openvdb::Vec3d centre = xform->indexToWorld(openvdb::Vec3d(24, 24, 24));
  dvec3 c(centre.x(), centre.y(), centre.z());
  dvec3 d = glm::normalize(dvec3(0.3, -0.7, 0.4));
  // From 0.6 world units before the centre to 0.6 after: inside (the slab is 2.35 wide).
  expectTransmittance(m, {c - 0.6 * d, d}, 1.2, scale * 1.2, 31);
}

TEST(ReferenceTracking, MajorantBoundsTrilinearDensityIncludingTiles) {
  initOpenVdb();
  auto sdf = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(20.0f, openvdb::Vec3f(0), 1.0f, 3.0f);
  openvdb::tools::sdfToFogVolume(*sdf);  // interior becomes active tiles
  ASSERT_GT(sdf->tree().activeTileCount(), 0u);
  for (const auto& grid : {sdf, test::makeNoiseGrid(40, 0.1)}) {
    ReferenceMedium m(grid, 2.0f);
    auto acc = m.accessor();
    Pcg32 rng(7, 7);
    openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
    int violations = 0, positive = 0;
    for (int i = 0; i < 200000; ++i) {
      dvec3 p;
      for (int a = 0; a < 3; ++a) p[a] = box.min()[a] - 2.0 + rng.uniform() * (box.dim()[a] + 4.0);
      if (i % 4 == 0) p = glm::floor(p) + dvec3(rng.nextUint() % 2 ? 0.0 : 1e-9);  // on voxel centres and cell borders
      openvdb::Vec3d w = grid->transform().indexToWorld(openvdb::Vec3d(p.x, p.y, p.z));
      double sigma = m.sigmaT(acc, dvec3(w.x(), w.y(), w.z()));
      positive += sigma > 0;
      if (m.majorantAtIndex(p) < sigma * (1 - 1e-6)) ++violations;
    }
    EXPECT_EQ(violations, 0);
    EXPECT_GT(positive, 1000);
  }
}

TEST(ReferenceTracking, EmptyGridIsEmptySpace) {
  initOpenVdb();
  auto grid = openvdb::FloatGrid::create(0.0f);
  ReferenceMedium m(grid, 5.0f);
  EXPECT_TRUE(m.empty());
  auto acc = m.accessor();
  Pcg32 rng(1, 1);
  TrackingStats stats;
  double t;
  EXPECT_FALSE(m.sampleCollision({dvec3(0), dvec3(0, 0, 1)}, 1e9, rng, acc, t, stats));
  EXPECT_EQ(m.ratioTracking({dvec3(0), dvec3(0, 0, 1)}, 1e9, rng, acc, stats), 1.0);
}
