// Tier d (DESIGN §7): the bundled smoke (volumes/smoke/smoke_sky.json: frame 12 of the
// smoke, 8 bounces) under the bundled sky map, whose sun disk lights it, at 24 x 24: the GPU path
// tracer and unbiased ReSTIR (temporal + spatial reuse; each sample the last frame of an
// independent run) against the CPU reference, per-pixel Z-tests with a Šidák correction and an
// aggregate z-test. About 6 s and 12 s on 2-core lavapipe.
#include "media/vdb_loader.h"
#include "reference/reference.h"
#include "render/gpu_volume.h"
#include "render/restir.h"
#include "support/gpu_fixture.h"
#include "support/reference_check.h"
#include "support/test_support.h"

#include <glm/glm.hpp>

using namespace plume;

namespace {

class GpuEnvMapSmoke : public test::GpuTest {};

constexpr int kFrame = 12;

Scene smokeSky() {
  Scene s = loadScene(test::sourcePath("volumes/smoke/smoke_sky.json"));
  s.camera.width = s.camera.height = 24;
  return s;
}

openvdb::FloatGrid::Ptr smokeGrid(const Scene& s) {
  LoadedGrid g = loadFloatGrid(s.medium().vdbPath(kFrame), s.medium().densityGrid);
  return g.grid;
}

Image reference(Scene s, openvdb::FloatGrid::Ptr grid, int spp) {
  s.render.spp = spp;
  s.render.seed = 2024;
  ref::ReferenceOptions opt;
  opt.progress = false;
  opt.frame = kFrame;
  return ref::renderReference(s, grid, opt);
}

}  // namespace

TEST_F(GpuEnvMapSmoke, PathTracerOnBundledSmokeUnderSkyMatchesReference) {
  const Scene s = smokeSky();
  auto grid = smokeGrid(s);
  const Image ref = reference(s, grid, 2048);
  Scene g = s;
  g.render.spp = 512;
  test::GpuRenderInfo info;
  const Image gpu = test::renderGpuPt(ctx(), compiler(), g, grid, kFrame, &info);
  test::ReferenceCheckOptions options;
  options.outputGroup = "gpu_envmap_smoke";
  test::expectMatchesReference(gpu, ref, "smoke_sky_pt", options);
  EXPECT_EQ(info.truncated, 0u);
}

TEST_F(GpuEnvMapSmoke, RestirOnBundledSmokeUnderSkyMatchesReference) {
  const Scene s = smokeSky();
  auto grid = smokeGrid(s);
  LoadedGrid loaded;
  loaded.grid = grid;
  loaded.name = "density";
  const BakedVolume bake = bakeVolume(loaded);
  GpuVolumeResources volume(ctx(), bake, s.medium().densityScale);
  RestirOptions o;  // temporal + spatial, pairwise MIS
  o.radius = 2;
  Restir restir(ctx(), compiler(), s, o);
  restir.setVolumes(volume, volume);
  // Independent runs of 3 frames; the last frame of each is one sample.
  const int runs = 256;
  const size_t n = size_t(s.camera.width) * s.camera.height * 3;
  std::vector<double> sum(n, 0.0), sum2(n, 0.0);
  glm::dvec3 meanSum(0.0), meanSum2(0.0);
  uint32_t dropped = 0;
  for (int run = 0; run < runs; ++run) {
    restir.resetHistory();
    Image last;
    for (int f = 0; f < 3; ++f) {
      last = restir.renderFrame(kFrame - 2 + f, uint32_t(run + 1));  // still camera and grid
      dropped += restir.takeDroppedCount();
    }
    glm::dvec3 m(0.0);
    for (size_t i = 0; i < n; ++i) {
      sum[i] += last.rgb[i];
      sum2[i] += double(last.rgb[i]) * last.rgb[i];
      m[int(i % 3)] += last.rgb[i];
    }
    m /= double(n / 3);
    meanSum += m;
    meanSum2 += m * m;
  }
  Image mean(s.camera.width, s.camera.height, true);
  for (size_t i = 0; i < n; ++i) {
    const double mu = sum[i] / runs;
    mean.rgb[i] = float(mu);
    mean.var[i] = float(std::max(0.0, sum2[i] / runs - mu * mu) / (runs - 1.0));
  }
  test::ReferenceCheckOptions options;
  options.outputGroup = "gpu_envmap_smoke";
  const glm::dvec3 mu = meanSum / double(runs);
  options.imageMeanVariance = glm::max(meanSum2 / double(runs) - mu * mu, glm::dvec3(0.0)) / (runs - 1.0);
  test::expectMatchesReference(mean, reference(s, grid, 2048), "smoke_sky_restir", options);
  EXPECT_EQ(dropped, 0u);
}
