#include "support/extreme.h"

#include "media/bake.h"
#include "media/vdb_loader.h"
#include "reference/reference.h"
#include "render/gpu_volume.h"
#include "render/restir.h"
#include "support/gpu_fixture.h"
#include "support/grids.h"
#include "support/scenes.h"

#include <glm/glm.hpp>

#include <chrono>
#include <cmath>
#include <limits>

namespace plume::test {
namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// A camera looking at the centre of a cube of side `size` world units from 1.3 sizes away (on
// +z), a sun from above and a dim sky: every length scales with `size`, nothing else does.
Scene sceneFor(double size, int pixels) {
  Scene s;
  s.path = "extreme-scene";
  const float c = float(0.5 * size);
  s.camera.base.position = glm::vec3(c, c * 1.3f, c + 1.3f * float(size));
  s.camera.base.lookAt = glm::vec3(c);
  s.camera.base.fovY = 40.0f;
  s.camera.width = s.camera.height = pixels;
  s.media.push_back(Medium{});
  s.media[0].albedo = glm::vec3(0.9f);
  s.lights = {sunLight({0.3f, 1.0f, -0.4f}, glm::vec3(3.0f)), skyLight({0.1f, 0.12f, 0.15f})};
  s.render.maxBounces = 6;
  return s;
}

ExtremeCase makeCase(std::string name, Scene scene, openvdb::FloatGrid::Ptr grid) {
  ExtremeCase c;
  c.name = std::move(name);
  c.replaced = sanitizeGrid(*grid);
  c.clamped = clampOpticalDepth(*grid, scene.media[0].densityScale);
  c.scene = scene;
  c.grid = grid;
  c.referenceScene = scene;
  c.referenceGrid = grid;
  return c;
}

// Values 10^(60 v - 30) for the noise cloud's v in (0, 1]: 1e-30 at its rim to 1e30 inside,
// and a NaN, an Inf and a negative voxel.
openvdb::FloatGrid::Ptr extremeValueGrid() {
  auto grid = makeNoiseGrid(24, 1.0 / 12, 23);
  for (auto it = grid->beginValueOn(); it; ++it) it.setValue(float(std::pow(10.0, 60.0 * double(*it) - 30.0)));
  auto acc = grid->getAccessor();
  acc.setValue(openvdb::Coord(12, 12, 12), std::numeric_limits<float>::quiet_NaN());
  acc.setValue(openvdb::Coord(11, 12, 12), -5.0f);
  acc.setValue(openvdb::Coord(12, 11, 12), std::numeric_limits<float>::infinity());
  acc.setValue(openvdb::Coord(3, 12, 12), 1e30f);  // a huge voxel in the thin rim
  return grid;
}

}  // namespace

std::vector<ExtremeCase> extremeCases(const ExtremeSize& size) {
  std::vector<ExtremeCase> out;
  const int px = size.pixels;
  // Scale invariance: voxels of 1e-4 and 1e3 world units, sigma_t scaled by 1/size so that every
  // optical depth matches the original (1/16 units per voxel); the reference is the original's.
  {
    Scene original = sceneFor(2.0, px);
    original.media[0].densityScale = 4.0f;
    auto originalGrid = makeNoiseGrid(32, 1.0 / 16, 22);
    for (double vs : {1e-4, 1e3}) {
      Scene s = sceneFor(32 * vs, px);
      s.media[0].densityScale = float(4.0 / (16 * vs));
      ExtremeCase c = makeCase(vs < 1 ? "scale_1e-4" : "scale_1e3", s, makeNoiseGrid(32, vs, 22));
      c.referenceScene = original;
      c.referenceGrid = originalGrid;
      out.push_back(std::move(c));
    }
  }
  // Dense and bright: density x300 (optical depth ~75 per voxel), albedo 0.99, many bounces.
  {
    Scene s = sceneFor(2.0, px);
    s.media[0].densityScale = 4.0f * 300.0f;
    s.media[0].albedo = glm::vec3(0.99f);
    s.render.maxBounces = size.bounces;
    out.push_back(makeCase("dense_bright", s, makeNoiseGrid(32, 1.0 / 16, 24)));
  }
  // Strongly forward scattering, the sun behind the smoke; strongly backward, the sun in front.
  for (float g : {0.99f, -0.99f}) {
    Scene s = sceneFor(2.0, px);
    s.media[0].densityScale = 4.0f;
    s.media[0].g = g;
    s.lights[0] = sunLight(g > 0 ? glm::vec3(0.15f, 0.25f, -1.0f) : glm::vec3(0.15f, 0.6f, 1.0f), glm::vec3(3.0f));
    out.push_back(makeCase(g > 0 ? "g+0.99_backlit" : "g-0.99", s, makeNoiseGrid(32, 1.0 / 16, 21)));
  }
  // Values from 1e-30 to 1e30 with NaN, Inf and negative voxels.
  {
    Scene s = sceneFor(2.0, px);
    s.media[0].densityScale = 1.0f;
    out.push_back(makeCase("values_1e-30_1e30", s, extremeValueGrid()));
  }
  // The camera inside a dense medium (optical depth ~3 to the box's faces).
  {
    Scene s = sceneFor(2.0, px);
    s.media[0].densityScale = 3.0f;
    s.camera.base.position = glm::vec3(1.0f, 1.0f, 1.1f);
    s.camera.base.lookAt = glm::vec3(1.3f, 0.8f, 0.0f);
    s.camera.base.fovY = 70.0f;
    ExtremeCase c = makeCase("camera_inside", s, makeBoxGrid(32, 1.0 / 16));
    c.mediumInView = false;  // everything is medium: no background pixel to compare with
    out.push_back(std::move(c));
  }
  // A single dense voxel (optical depth 5 per voxel) in empty space, seen from close up.
  {
    Scene s = sceneFor(2.0, px);
    s.media[0].densityScale = 80.0f;
    s.camera.base.position = glm::vec3(0.0f, 0.08f, 0.35f);
    s.camera.base.lookAt = glm::vec3(0.0f);
    initOpenVdb();
    auto grid = openvdb::FloatGrid::create(0.0f);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(1.0 / 16));
    grid->setName("density");
    grid->getAccessor().setValue(openvdb::Coord(0), 1.0f);
    ExtremeCase c = makeCase("single_voxel", s, grid);
    c.mediumInView = false;  // a small blob
    out.push_back(std::move(c));
  }
  // An empty grid: the environment only.
  {
    initOpenVdb();
    auto grid = openvdb::FloatGrid::create(0.0f);
    grid->setName("density");
    Scene s = sceneFor(2.0, px);
    s.media[0].densityScale = 4.0f;
    ExtremeCase c = makeCase("empty_grid", s, grid);
    c.mediumInView = false;
    out.push_back(std::move(c));
  }
  return out;
}

uint64_t countNonFinite(const Image& image) {
  uint64_t n = 0;
  for (float v : image.rgb) n += !std::isfinite(v);
  return n;
}

EstimatorRun runReferenceCase(const ExtremeCase& c, int spp, uint32_t seed) {
  Scene s = c.referenceScene;
  s.render.spp = spp;
  s.render.seed = seed;
  ref::ReferenceOptions opt;
  opt.progress = false;
  ref::ReferenceStats stats;
  EstimatorRun run;
  const auto start = Clock::now();
  run.image = ref::renderReference(s, c.referenceGrid, opt, &stats);
  run.seconds = secondsSince(start);
  run.truncated = stats.truncatedTracking;
  run.nonFinite = countNonFinite(run.image);
  return run;
}

EstimatorRun runPtCase(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const ExtremeCase& c, int spp) {
  Scene s = c.scene;
  s.render.spp = spp;
  GpuRenderInfo info;
  EstimatorRun run;
  const auto start = Clock::now();
  run.image = renderGpuPt(ctx, compiler, s, c.grid, 1, &info);
  run.seconds = secondsSince(start);
  run.truncated = info.truncated;
  run.nonFinite = countNonFinite(run.image);
  return run;
}

EstimatorRun runRestirCase(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const ExtremeCase& c, int runs,
                           uint32_t mis) {
  RestirOptions o;
  o.rounds = 1;
  o.radius = 2;
  o.historyCap = 0;
  o.mis = mis;
  return runRestirCase(ctx, compiler, c, runs, o);
}

EstimatorRun runRestirCase(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const ExtremeCase& c, int runs,
                           const RestirOptions& o, int framesPerRun) {
  const auto start = Clock::now();
  auto upload = [&](openvdb::FloatGrid::Ptr grid) {
    LoadedGrid loaded;
    loaded.grid = grid;
    loaded.name = "density";
    return std::make_unique<GpuVolumeResources>(ctx, bakeVolume(loaded), c.scene.media[0].densityScale);
  };
  const std::unique_ptr<GpuVolumeResources> current = upload(c.grid);
  const std::unique_ptr<GpuVolumeResources> previous = c.previousGrid ? upload(c.previousGrid) : nullptr;
  const GpuVolumeResources& volume = *current;
  const GpuVolumeResources& before = previous ? *previous : volume;
  Restir restir(ctx, compiler, c.scene, o);
  // Mean and variance of the mean over independent runs, per pixel and of the image mean.
  const size_t n = size_t(3) * c.scene.camera.width * c.scene.camera.height;
  std::vector<double> sum(n, 0.0), sum2(n, 0.0);
  glm::dvec3 meanSum(0.0), meanSum2(0.0);
  EstimatorRun run;
  for (int r = 0; r < runs; ++r) {
    restir.resetHistory();
    Image im;
    for (int f = 1; f <= framesPerRun; ++f) {
      if (f < framesPerRun) restir.setVolumes(before, before);
      else restir.setVolumes(volume, before);
      im = restir.renderFrame(f, uint32_t(r + 1));
    }
    glm::dvec3 m(0.0);
    for (size_t i = 0; i < n; ++i) {
      sum[i] += im.rgb[i], sum2[i] += double(im.rgb[i]) * im.rgb[i];
      m[int(i % 3)] += im.rgb[i];
    }
    m /= double(n / 3);
    meanSum += m, meanSum2 += m * m;
  }
  run.truncated = volume.truncatedCount() + volume.loopLimitCount() + restir.takeDroppedCount();
  if (previous) run.truncated += previous->truncatedCount() + previous->loopLimitCount();
  run.image = Image(c.scene.camera.width, c.scene.camera.height, true);
  for (size_t i = 0; i < n; ++i) {
    const double mean = sum[i] / runs;
    run.image.rgb[i] = float(mean);
    run.image.var[i] = float(std::max(0.0, sum2[i] / runs - mean * mean) / (runs - 1.0));
  }
  const glm::dvec3 mean = meanSum / double(runs);
  run.hasImageMeanVariance = true;
  run.imageMeanVariance = glm::max(meanSum2 / double(runs) - mean * mean, glm::dvec3(0.0)) / (runs - 1.0);
  run.seconds = secondsSince(start);
  run.nonFinite = countNonFinite(run.image);
  return run;
}

}  // namespace plume::test
