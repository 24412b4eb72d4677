// The extreme-media suite in CI (issue 13, support/extreme.h), small: each case rendered by the
// GPU path tracer and by ReSTIR (pairwise MIS, spatial reuse) and checked against the CPU
// reference (per-pixel Z-test with Šidák and the aggregate z-test on the image mean,
// support/reference_check.h), with no truncated tracking loop and no non-finite value anywhere.
// The larger variants and the suite's table: test_extreme_suite_slow.cpp.
#include "io/image.h"
#include "shaders/shared/restir_types.h"
#include "support/extreme.h"
#include "support/gpu_fixture.h"
#include "support/grids.h"
#include "support/reference_check.h"
#include "support/test_support.h"

#include <openvdb/io/File.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>

using namespace plume;

namespace {

class ExtremeSuite : public test::GpuTest {};

struct Counts {
  int ptSpp = 512, refSpp = 1024, restirRuns = 128;
};

test::ExtremeCase caseNamed(const std::string& name, const test::ExtremeSize& size) {
  for (test::ExtremeCase& c : test::extremeCases(size))
    if (c.name == name) return c;
  throw std::invalid_argument("no extreme case " + name);
}

void expectClean(const test::EstimatorRun& run, const std::string& label) {
  EXPECT_EQ(run.truncated, 0u) << label;
  EXPECT_EQ(run.nonFinite, 0u) << label;
  std::printf("[extreme] %s: %.2f s\n", label.c_str(), run.seconds);
}

// The medium is in view: many pixels differ from the corner's background.
void expectMediumInView(const Image& image, const std::string& label) {
  int medium = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      medium += glm::any(glm::greaterThan(glm::abs(image.pixel(x, y) - image.pixel(0, 0)), glm::vec3(1e-3f)));
  EXPECT_GT(medium, image.width * image.height / 5) << label;
}

void checkCase(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const test::ExtremeCase& c, const Counts& n) {
  test::ReferenceCheckOptions options;
  options.outputGroup = "extreme_suite";
  const test::EstimatorRun ref = test::runReferenceCase(c, n.refSpp);
  expectClean(ref, c.name + " reference");
  const test::EstimatorRun pt = test::runPtCase(ctx, compiler, c, n.ptSpp);
  expectClean(pt, c.name + " pt");
  test::expectMatchesReference(pt.image, ref.image, c.name + "_pt", options);
  if (c.mediumInView) expectMediumInView(pt.image, c.name);
  if (!c.restir) return;
  const test::EstimatorRun rs = test::runRestirCase(ctx, compiler, c, n.restirRuns, shared::RS_MIS_PAIRWISE);
  expectClean(rs, c.name + " restir");
  options.imageMeanVariance = rs.imageMeanVariance;
  test::expectMatchesReference(rs.image, ref.image, c.name + "_restir", options);
}

}  // namespace

TEST_F(ExtremeSuite, TinyVoxelsRenderLikeTheOriginal) {
  checkCase(ctx(), compiler(), caseNamed("scale_1e-4", {16, 256}), {});
}

TEST_F(ExtremeSuite, HugeVoxelsRenderLikeTheOriginal) {
  checkCase(ctx(), compiler(), caseNamed("scale_1e3", {16, 256}), {});
}

TEST_F(ExtremeSuite, DenseAndBright) {
  // 256 bounces at albedo 0.99: long paths on both sides, so a smaller image. The path tracer
  // only: ReSTIR's part (another ~30 s on the shared VM, which would take this case past a
  // minute) is ExtremeSuiteSlow.DenseAndBrightRestir.
  test::ExtremeCase c = caseNamed("dense_bright", {8, 256});
  c.restir = false;
  checkCase(ctx(), compiler(), c, {256, 256, 256});
}

// 512 ReSTIR runs: with the candidates' delta tracking in the mean field (session 27) 128 runs
// left one pixel at z -5.46, the light forward-scattered through the slab a rare bright event
// (512 runs: worst pixel z -2.66, relMSE 0.079; the closed-form sampling before it: -2.71, 0.100).
TEST_F(ExtremeSuite, StronglyForwardScatteringBacklit) {
  checkCase(ctx(), compiler(), caseNamed("g+0.99_backlit", {16, 256}), {512, 1024, 512});
}

TEST_F(ExtremeSuite, StronglyBackwardScattering) {
  checkCase(ctx(), compiler(), caseNamed("g-0.99", {16, 256}), {});
}

TEST_F(ExtremeSuite, ValuesFrom1em30To1e30WithNanInfNegativeRenderFiniteInBoundedTime) {
  const test::ExtremeCase c = caseNamed("values_1e-30_1e30", {12, 256});
  EXPECT_EQ(c.replaced, 3u);  // the NaN, the Inf and the negative voxel
  EXPECT_GT(c.clamped, 0u);   // values above optical depth kMaxVoxelOpticalDepth per voxel
  // Bounded time: no step cap reached anywhere (expectClean), a few seconds each at this size.
  const test::EstimatorRun ref = test::runReferenceCase(c, 512);
  expectClean(ref, c.name + " reference");
  const test::EstimatorRun pt = test::runPtCase(ctx(), compiler(), c, 256);
  expectClean(pt, c.name + " pt");
  const test::EstimatorRun rs = test::runRestirCase(ctx(), compiler(), c, 64, shared::RS_MIS_PAIRWISE);
  expectClean(rs, c.name + " restir");
  // Both pass the per-pixel and the aggregate test. (Until session 6 the path tracer's image
  // mean was ~1.2% low here, aggregate z -5..-7: lavapipe's shared loop limit had cut its walks,
  // see volume/loop_guard.glsl; expectClean now counts such cuts as truncations. Until session 8
  // ReSTIR's candidates tracked the voxel means, far from the clamped fine field here: fireflies,
  // relMSE ~2.6; its field is now the fine density itself in such voxels, volume/walk.glsl
  // "exact voxels".)
  test::ReferenceCheckOptions options;
  options.outputGroup = "extreme_suite";
  const test::ReferenceCheck check = test::checkAgainstReference(pt.image, ref.image, options);
  EXPECT_TRUE(check.pass()) << check.summary();
  options.imageMeanVariance = rs.imageMeanVariance;
  test::expectMatchesReference(rs.image, ref.image, c.name + "_restir", options);
  std::printf("[extreme] %s pt: %s\n", c.name.c_str(), check.aggregate.summary().c_str());
}

TEST_F(ExtremeSuite, CameraInsideADenseMedium) {
  checkCase(ctx(), compiler(), caseNamed("camera_inside", {16, 256}), {});
}

// 512 ReSTIR runs: with two spatial neighbours (the default since session 24) 128 runs left one
// pixel at z -5.11, a rare bright event seen too seldom (512 runs: worst pixel z -3.03, the
// aggregate z <= 1.07; notes/restir.md "Session 25").
TEST_F(ExtremeSuite, SingleVoxelInEmptySpace) {
  checkCase(ctx(), compiler(), caseNamed("single_voxel", {16, 256}), {512, 1024, 512});
}

TEST_F(ExtremeSuite, EmptyGridShowsTheEnvironmentInEveryEstimator) {
  const test::ExtremeCase c = caseNamed("empty_grid", {8, 256});
  const glm::vec3 sky = c.scene.lights[1].radiance;
  const test::EstimatorRun ref = test::runReferenceCase(c, 4);
  const test::EstimatorRun pt = test::runPtCase(ctx(), compiler(), c, 4);
  const test::EstimatorRun rs = test::runRestirCase(ctx(), compiler(), c, 2, shared::RS_MIS_PAIRWISE);
  for (const auto* run : {&ref, &pt, &rs}) {
    expectClean(*run, "empty_grid");
    for (int y = 0; y < run->image.height; ++y)
      for (int x = 0; x < run->image.width; ++x) EXPECT_EQ(run->image.pixel(x, y), sky);
  }
}

// The issue's case end to end: a VDB file with values 1e-30 .. 1e30 and NaN/Inf/negative voxels,
// rendered at 32², 4 spp by `plume reference`, `plume render --mode pt` and `--mode restir` at
// 64 bounces: each finishes in seconds, warns about the replaced and the clamped values,
// truncates no tracking loop and writes a finite image. (64², 16 spp: reference ~4 s, pt ~18 s,
// restir ~25 s on 2 cores, most of it the tail walking the clamped interior.)
TEST(ExtremeSuiteCli, ValuesFileRendersInEveryModeWithWarnings) {
  const std::string dir = test::outputDir("extreme_suite_cli");
  auto grid = test::makeNoiseGrid(24, 1.0 / 12, 23);
  for (auto it = grid->beginValueOn(); it; ++it) it.setValue(float(std::pow(10.0, 60.0 * double(*it) - 30.0)));
  auto acc = grid->getAccessor();
  acc.setValue(openvdb::Coord(12, 12, 12), std::numeric_limits<float>::quiet_NaN());
  acc.setValue(openvdb::Coord(11, 12, 12), -5.0f);
  acc.setValue(openvdb::Coord(12, 11, 12), std::numeric_limits<float>::infinity());
  openvdb::io::File(dir + "/values.vdb").write({grid});
  std::ofstream(dir + "/values.json") << R"({
  "camera": { "position": [1.0, 1.3, 3.6], "look_at": [1.0, 1.0, 1.0], "up": [0, 1, 0], "fov_y": 40,
              "width": 32, "height": 32 },
  "media": [ { "vdb": "values.vdb", "density_grid": "density", "density_scale": 1.0, "albedo": [0.9, 0.9, 0.9] } ],
  "lights": [ { "type": "sun", "to_light": [0.3, 1.0, -0.4], "irradiance": [3, 3, 3] },
              { "type": "environment", "radiance": [0.1, 0.12, 0.15] } ],
  "render": { "max_bounces": 64, "spp": 4, "seed": 1 }
})";
  for (const std::vector<std::string>& mode : std::vector<std::vector<std::string>>{
           {"reference"}, {"render", "--mode", "pt"}, {"render", "--mode", "restir"}}) {
    const std::string out = dir + "/" + mode.back() + ".exr";
    std::vector<std::string> args = mode;
    args.insert(args.end(), {dir + "/values.json", "-o", out});
    const test::RunResult r = test::runPlume(args);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("replaced by 0"), std::string::npos) << mode.back() << "\n" << r.output;
    EXPECT_NE(r.output.find("clamped to it"), std::string::npos) << mode.back() << "\n" << r.output;
    const Image image = readExr(out);
    EXPECT_EQ(image.meta.at("tracking_truncated"), "0") << mode.back();
    EXPECT_EQ(test::countNonFinite(image), 0u) << mode.back();
  }
}

