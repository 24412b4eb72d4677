// The bundled many-lights city (volumes/city/city.json) in full: the path tracer against the CPU
// reference on the scene's own framing at 32 x 32, its 4 bounces and frame 24's grid (the fast
// suite's test_city.cpp checks a 20 x 20 crop). Label `slow`: about 2 minutes on 2 cores; resolves about 2%.
#include "media/vdb_loader.h"
#include "support/gpu_fixture.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

using namespace plume;

class CityGpuSlowTest : public test::GpuTest {};

TEST_F(CityGpuSlowTest, PathTracerMatchesReferenceOnTheWholeCityPicture) {
  Scene s = loadScene(test::sourcePath("volumes/city/city.json"));
  s.camera.width = s.camera.height = 32;
  LoadedGrid grid = loadFloatGrid(s.medium().vdbPath(24), s.medium().densityGrid);
  clampOpticalDepth(*grid.grid, s.medium().densityScale);
  const test::ReferenceCheck check =
      test::expectPtMatchesReference(ctx(), compiler(), s, grid.grid, 8192, 16384, "city_full", "city", "emitters", 0.95f);
  EXPECT_LT(check.aggregate.resolvableBias().x, 0.035) << "too few samples for the test to mean much";
}
