// Which pixels a Monte Carlo reference resolves (support/resolution.h), and the per-pixel test
// that leaves the others out while the aggregate test keeps them (support/reference_check.h).
// The case behind them: ReSTIR on the Blender fire's thin wisps (notes/restir.md, "Thin wisps").
#include "media/vdb_loader.h"
#include "support/reference_check.h"
#include "support/resolution.h"

#include <glm/glm.hpp>
#include <gtest/gtest.h>

#include <cmath>

using namespace plume;

namespace {

// Voxels [lo, hi] (inclusive) of `grid` set to `value`.
void fillBox(openvdb::FloatGrid& grid, openvdb::Coord lo, openvdb::Coord hi, float value) {
  grid.denseFill(openvdb::CoordBBox(lo, hi), value, true);
}

// Two boxes of 16 voxels in depth (voxel size h = 1/16: depth 1), seen face-on from far away
// down -z (8x8 pixels of 0.5 x 0.5 at z = 0): columns 0-2 see a dense box (density 1), columns
// 5-7 a wisp (density 1e-6), rows 0 and 7 nothing, not even half a pixel further out. Along the
// axis the trilinear ramps at the two faces add half a voxel each, so a face-on ray crosses
// tau = scale * density * 16 * h.
struct TwoBoxes {
  openvdb::FloatGrid::Ptr grid;
  Scene scene;
  TwoBoxes() {
    initOpenVdb();
    grid = openvdb::FloatGrid::create(0.0f);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(1.0 / 16));
    fillBox(*grid, openvdb::Coord(-40, -18, 0), openvdb::Coord(-1, 17, 15), 1.0f);
    fillBox(*grid, openvdb::Coord(1, -18, 0), openvdb::Coord(40, 17, 15), 1e-6f);
    scene.path = "test-scene";
    scene.camera.base.position = {0.0f, 0.0f, 100.0f};
    scene.camera.base.lookAt = {0.0f, 0.0f, 0.0f};
    scene.camera.base.up = {0.0f, 1.0f, 0.0f};
    scene.camera.base.fovY = 2.0f * float(glm::degrees(std::atan(2.0 / 100.0)));  // y in [-2, 2] at z = 0
    scene.camera.width = scene.camera.height = 8;
    Medium m;
    m.densityScale = 2.0f;
    scene.media.push_back(m);
  }
};

TEST(ReferenceResolution, DenseWispAndEmptyPixelsOfTwoBoxes) {
  TwoBoxes b;
  const int spp = 8192;
  const test::ResolutionMap map = test::referenceResolution(b.scene, *b.grid, spp);
  ASSERT_EQ(map.width, 8);
  // Rows 1 and 6 and columns 3 and 4 cross the boxes' edges: not asserted.
  const double tauDense = 2.0 * 1.0, tauWisp = 2.0 * 1e-6;
  for (int y = 2; y < 6; ++y) {
    for (int x : {0, 1, 2}) {
      const size_t i = size_t(y * 8 + x);
      EXPECT_EQ(map.pixels[i], test::PixelResolution::Resolved) << x << "," << y;
      EXPECT_NEAR(map.collisionProbability[i], -std::expm1(-tauDense), 0.02) << x << "," << y;
    }
    for (int x : {5, 6, 7}) {
      const size_t i = size_t(y * 8 + x);
      EXPECT_EQ(map.pixels[i], test::PixelResolution::Unresolved) << x << "," << y;
      EXPECT_NEAR(map.collisionProbability[i], tauWisp, 0.02 * tauWisp) << x << "," << y;
    }
  }
  for (int x = 0; x < 8; ++x) {
    EXPECT_EQ(map.pixels[size_t(x)], test::PixelResolution::Empty) << x;
    EXPECT_EQ(map.pixels[size_t(7 * 8 + x)], test::PixelResolution::Empty) << x;
  }
  // A reference with enough samples resolves the wisp too: N * P >= 100.
  const test::ResolutionMap many = test::referenceResolution(b.scene, *b.grid, int(std::ceil(101.0 / tauWisp)));
  EXPECT_EQ(many.pixels[size_t(3 * 8 + 6)], test::PixelResolution::Resolved);
}

// A 2x1 image: pixel 0 agrees with the reference; pixel 1 is the thin-wisp case, a small
// positive value with a small variance against a reference of exactly 0 with variance 0.
TEST(ReferenceCheck, UnresolvedPixelsLeaveOnlyThePerPixelTest) {
  Image ref(2, 1, true), img(2, 1, true);
  for (int c = 0; c < 3; ++c) {
    ref.rgb[size_t(c)] = 1.0f, ref.var[size_t(c)] = 1e-4f;
    img.rgb[size_t(c)] = 1.0f, img.var[size_t(c)] = 1e-4f;
    img.rgb[size_t(3 + c)] = 1e-9f, img.var[size_t(3 + c)] = 1e-21f;  // z = 31.6
  }
  test::ReferenceCheckOptions all;
  const test::ReferenceCheck fails = test::checkAgainstReference(img, ref, all);
  EXPECT_FALSE(fails.pixels.pass);
  EXPECT_EQ(fails.pixels.worstX, 1);
  test::ReferenceCheckOptions resolved;
  resolved.unresolved = {false, true};
  const test::ReferenceCheck passes = test::checkAgainstReference(img, ref, resolved);
  EXPECT_TRUE(passes.pixels.pass) << passes.summary();
  EXPECT_EQ(passes.pixels.tests, 3u);
  EXPECT_EQ(passes.pixels.worstX, 0);
  EXPECT_EQ(passes.unresolvedPixels, 1u);
  EXPECT_NE(passes.summary().find("unresolved"), std::string::npos);
  // The aggregate test still sees the unresolved pixel: a large difference there fails it.
  for (int c = 0; c < 3; ++c) img.rgb[size_t(3 + c)] = 0.5f;
  EXPECT_FALSE(test::checkAgainstReference(img, ref, resolved).aggregate.pass);
  EXPECT_TRUE(test::checkAgainstReference(img, ref, resolved).pixels.pass);
  // A resolved pixel that disagrees still fails.
  img.rgb[0] = 2.0f;
  EXPECT_FALSE(test::checkAgainstReference(img, ref, resolved).pixels.pass);
}

}  // namespace
