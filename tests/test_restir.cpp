// Volumetric ReSTIR (DESIGN §4.2, §7); its MIS weights: tests/test_restir_mis.cpp. Tier d: the
// ReSTIR estimator against the independent CPU reference, per-pixel Z-test with a Šidák
// correction and an aggregate z-test on the image mean (support/reference_check.h), validation
// layers on: candidates and final shading alone; spatial reuse (pairwise MIS and the generalised
// balance heuristic); temporal reuse with a still and a moving camera; and restir-biased, whose
// bias is measured and bounded. Each GPU sample is the last frame of an independent run (its own
// seed sequence), so samples are independent and the variance of the mean is estimated honestly
// even with temporal reuse; so is that of the image mean, from each run's image mean, though
// spatial reuse correlates the pixels of a run.
#include "core/error.h"
#include "media/vdb_loader.h"
#include "reference/reference.h"
#include "render/gpu_scene.h"
#include "render/pixel_order.h"
#include "render/restir.h"
#include "support/gpu_fixture.h"
#include "support/grids.h"
#include "support/reference_check.h"
#include "support/run_accumulator.h"
#include "support/scenes.h"
#include "support/test_support.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <initializer_list>
#include <memory>
#include <random>
#include <stdexcept>

using namespace plume;

namespace {

class GpuRestir : public test::GpuTest {};

Scene baseScene(int size) {
  Scene s = test::sceneWithCamera("test-scene", {1.0f, 1.2f, 3.6f}, {1.0f, 1.0f, 1.0f}, size);
  Medium m;
  m.densityScale = 6.0f;
  m.albedo = glm::vec3(0.8f, 0.85f, 0.9f);
  m.g = 0.4f;
  s.media.push_back(m);
  s.lights = {test::sunLight({0.4f, 1.0f, 0.3f}, {3.0f, 2.8f, 2.5f}), test::skyLight({0.10f, 0.12f, 0.16f})};
  s.render.maxBounces = 1;
  return s;
}

// Environment overrides of the suite's run counts and seeds, for investigating a failure (more
// runs, other seeds). The thresholds were designed for the defaults: an override is announced
// on stdout, recorded in the test's XML properties and named in failure messages.
constexpr const char* kKnobs[] = {"PLUME_RESTIR_RUNS", "PLUME_RESTIR_SEQ", "PLUME_RESTIR_REF_SEED"};

int knob(const char* name, int defaultValue) {
  const char* v = std::getenv(name);
  if (!v) return defaultValue;
  const int value = std::atoi(v);
  std::printf("[restir] NON-DEFAULT RUN: %s=%d (default %d); the test thresholds were designed for the defaults\n",
              name, value, defaultValue);
  ::testing::Test::RecordProperty(name, value);
  return value;
}

// "NAME=value ..." of the overrides in effect, or "".
std::string overrides() {
  std::string out;
  for (const char* name : kKnobs) {
    if (const char* v = std::getenv(name)) out += std::string(out.empty() ? "" : " ") + name + "=" + v;
  }
  return out;
}

struct RunSpec {
  int runs = 256;           // independent runs (PLUME_RESTIR_RUNS overrides it)
  int framesPerRun = 1;     // frames rendered per run; the last one is the sample
  int firstFrame = 1;
  bool animatedGrid = false;
  int sequenceOffset = 0;   // added to each run's seed sequence (PLUME_RESTIR_SEQ overrides it)
};

std::shared_ptr<const BakedVolume> bakeOf(openvdb::FloatGrid::Ptr grid) {
  LoadedGrid loaded;
  loaded.grid = grid;
  loaded.name = "density";
  return std::make_shared<BakedVolume>(bakeVolume(loaded));
}

struct RestirRun {
  Image mean;
  glm::dvec3 imageMeanVariance{0.0};  // see test::RunAccumulator
  uint32_t dropped = 0;
  // Tracking loops cut by the step cap or by the driver's loop budget (volume/loop_guard.glsl),
  // as support/extreme.cpp counts them: any is a truncated, biased image.
  uint32_t truncated = 0;
  double seconds = 0;
};

// Runs ReSTIR with `options`; gridAt(frame) gives the grid of each frame.
template <class GridAt>
RestirRun runRestir(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const Scene& scene, const RestirOptions& options,
                    const RunSpec& spec, GridAt gridAt) {
  const auto start = std::chrono::steady_clock::now();
  plume::Restir restir(ctx, compiler, scene, options);
  test::RunAccumulator acc;
  RestirRun out;
  // Volumes of each frame, baked once.
  std::vector<std::unique_ptr<GpuVolumeResources>> volumes;
  for (int f = 0; f < spec.framesPerRun; ++f) {
    if (f > 0 && !spec.animatedGrid) break;
    volumes.push_back(std::make_unique<GpuVolumeResources>(ctx, *bakeOf(gridAt(spec.firstFrame + f)),
                                                           scene.media[0].densityScale));
  }
  const int runs = knob("PLUME_RESTIR_RUNS", spec.runs);
  if (runs < 2) throw std::invalid_argument("PLUME_RESTIR_RUNS: at least 2 runs are needed for a variance");
  const uint32_t sequenceOffset = uint32_t(knob("PLUME_RESTIR_SEQ", spec.sequenceOffset));
  for (int run = 0; run < runs; ++run) {
    restir.resetHistory();
    Image last;
    for (int f = 0; f < spec.framesPerRun; ++f) {
      const size_t cur = spec.animatedGrid ? size_t(f) : 0, prev = spec.animatedGrid && f > 0 ? size_t(f - 1) : cur;
      restir.setVolumes(*volumes[cur], *volumes[prev]);
      last = restir.renderFrame(spec.firstFrame + f, uint32_t(run + 1) + sequenceOffset);
      out.dropped += restir.takeDroppedCount();
    }
    acc.add(last);
  }
  for (const auto& v : volumes) out.truncated += v->truncatedCount() + v->loopLimitCount();
  out.mean = acc.image(scene.camera.width, scene.camera.height);
  out.imageMeanVariance = acc.imageMeanVariance();
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

Image reference(Scene s, openvdb::FloatGrid::Ptr grid, int spp, int frame = 1) {
  s.render.spp = spp;
  s.render.seed = knob("PLUME_RESTIR_REF_SEED", 777);
  ref::ReferenceOptions opt;
  opt.progress = false;
  opt.frame = frame;
  return ref::renderReference(s, grid, opt);
}

RestirOptions noReuse() {
  RestirOptions o;
  o.rounds = 0;
  o.historyCap = 0;
  return o;
}

test::ReferenceCheckOptions checkOptions(const RestirRun& run) {
  test::ReferenceCheckOptions options;
  options.imageMeanVariance = run.imageMeanVariance;
  options.outputGroup = "restir";
  return options;
}

void expectMatches(const RestirRun& run, const Image& ref, const std::string& name) {
  SCOPED_TRACE(overrides().empty() ? "default run counts and seeds" : "NON-DEFAULT: " + overrides());
  test::expectMatchesReference(run.mean, ref, name, checkOptions(run));
  EXPECT_EQ(run.dropped, 0u) << name;
  EXPECT_EQ(run.truncated, 0u) << name;
  std::printf("[restir] %s: %.1f s\n", name.c_str(), run.seconds);
}

// Frames 1 to 4 of one run of `o` on `s`: frame f over volumes[f - 1] with volumes[f - 2] as the
// history's, or over volumes[0] throughout where there is one volume.
std::vector<Image> restirFrames(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const Scene& s,
                                const RestirOptions& o,
                                const std::vector<std::unique_ptr<GpuVolumeResources>>& volumes) {
  Restir restir(ctx, compiler, s, o);
  const bool animated = volumes.size() > 1;
  std::vector<Image> out;
  for (int f = 1; f <= 4; ++f) {
    const size_t cur = animated ? size_t(f - 1) : 0, prev = animated ? size_t(std::max(f - 2, 0)) : 0;
    restir.setVolumes(*volumes[cur], *volumes[prev]);
    out.push_back(restir.renderFrame(f, 1));
  }
  return out;
}

// The baked grids of noise clouds of the given seeds, one per frame (restirFrames: one grid held
// still, four animated).
std::vector<std::unique_ptr<GpuVolumeResources>> noiseVolumes(gpu::Context& ctx, const Scene& s,
                                                              std::initializer_list<unsigned> seeds) {
  std::vector<std::unique_ptr<GpuVolumeResources>> volumes;
  for (unsigned seed : seeds) {
    volumes.push_back(std::make_unique<GpuVolumeResources>(ctx, *bakeOf(test::makeNoiseGrid(40, 1.0 / 20, seed)),
                                                           s.media[0].densityScale));
  }
  return volumes;
}

// Channels of two runs' frames whose bits differ, and channels lit in the first run.
struct BitDifferences {
  size_t differ = 0, lit = 0;
};
BitDifferences bitDifferences(const std::vector<Image>& a, const std::vector<Image>& b) {
  BitDifferences d;
  for (size_t f = 0; f < a.size(); ++f) {
    for (size_t i = 0; i < a[f].rgb.size(); ++i) {
      d.differ += std::memcmp(&a[f].rgb[i], &b[f].rgb[i], sizeof(float)) != 0 ? 1 : 0;
      d.lit += a[f].rgb[i] > 0.0f ? 1 : 0;
    }
  }
  return d;
}

}  // namespace


// --- Tier d: images against the CPU reference -------------------------------------------------

TEST_F(GpuRestir, CandidatesWithoutReuseMatchReference) {
  Scene s = baseScene(16);
  auto grid = test::makeNoiseGrid(40, 1.0 / 20, 2);
  RunSpec spec;
  RestirRun run = runRestir(ctx(), compiler(), s, noReuse(), spec, [&](int) { return grid; });
  expectMatches(run, reference(s, grid, 512), "no_reuse");
}

TEST_F(GpuRestir, MultipleScatteringWithoutReuseMatchesReference) {
  Scene s = baseScene(16);
  // Four vertices with Russian roulette from the first: HG direction sampling, coarse tracking
  // from inside the medium and the roulette's probability all enter the candidates' pdf.
  s.render.maxBounces = 4;
  s.render.rrStartBounce = 1;
  auto grid = test::makeNoiseGrid(40, 1.0 / 20, 3);
  RunSpec spec;
  // Multi-bounce weights are heavy-tailed: 256 runs underestimate a pixel's variance now and
  // then (a z of -4.4 on one pixel with 256 runs, 2.7 worst with 2048 against the same
  // reference); 1024 runs keep the variance estimate honest.
  spec.runs = 1024;
  RestirRun run = runRestir(ctx(), compiler(), s, noReuse(), spec, [&](int) { return grid; });
  expectMatches(run, reference(s, grid, 512), "no_reuse_multi");
}

TEST_F(GpuRestir, SpatialReusePairwiseMatchesReference) {
  Scene s = baseScene(16);
  auto grid = test::makeNoiseGrid(40, 1.0 / 20, 2);
  RestirOptions o = noReuse();
  o.rounds = 1;
  o.radius = 6;
  RunSpec spec;
  RestirRun run = runRestir(ctx(), compiler(), s, o, spec, [&](int) { return grid; });
  expectMatches(run, reference(s, grid, 512), "spatial_pairwise");
}

TEST_F(GpuRestir, SpatialReuseGbhMatchesReference) {
  Scene s = baseScene(16);
  auto grid = test::makeNoiseGrid(40, 1.0 / 20, 2);
  RestirOptions o = noReuse();
  o.rounds = 1;
  o.radius = 6;
  o.mis = shared::RS_MIS_GBH;
  RunSpec spec;
  RestirRun run = runRestir(ctx(), compiler(), s, o, spec, [&](int) { return grid; });
  expectMatches(run, reference(s, grid, 512), "spatial_gbh");
}

// ReSTIR over `frames` frames of a still camera over a still noise cloud, against the reference.
void expectStillCameraMatches(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const RestirOptions& o, int frames,
                              const char* label) {
  const Scene s = baseScene(16);
  auto grid = test::makeNoiseGrid(40, 1.0 / 20, 2);
  RunSpec spec;
  spec.framesPerRun = frames;
  RestirRun run = runRestir(ctx, compiler, s, o, spec, [&](int) { return grid; });
  expectMatches(run, reference(s, grid, 512), label);
}

TEST_F(GpuRestir, TemporalAndSpatialStillCameraMatchesReference) {
  RestirOptions o;  // defaults: temporal (c = 20) + one spatial round, pairwise
  o.radius = 6;
  expectStillCameraMatches(ctx(), compiler(), o, 4, "temporal_still");
}

// The same with render.density_filter = exact (8 texel reads with exact weights): the default,
// auto, reads through the texture unit where its filter is measured exact (lavapipe), so this keeps
// the 8 reads tested on such a device (candidates, the temporal history's lookups, shading).
TEST_F(GpuRestir, ExactLookupsTemporalAndSpatialMatchReference) {
  Scene s = baseScene(16);
  s.render.densityFilter = "exact";
  auto grid = test::makeNoiseGrid(40, 1.0 / 20, 2);
  RestirOptions o;
  o.radius = 6;
  {
    Restir probe(ctx(), compiler(), s, o);
    EXPECT_FALSE(probe.features().hardwareFilter);
  }
  RunSpec spec;
  spec.framesPerRun = 4;
  RestirRun run = runRestir(ctx(), compiler(), s, o, spec, [&](int) { return grid; });
  expectMatches(run, reference(s, grid, 512), "temporal_still_exact");
}

// Five lights: each candidate vertex samples one light chosen in proportion to its estimated
// power (render/restir.cpp); a dim light must still be found.
TEST_F(GpuRestir, ManyLightsChosenByPowerMatchReference) {
  Scene s = baseScene(16);
  auto point = [](glm::vec3 p, glm::vec3 intensity) {
    Light l;
    l.type = LightType::Point;
    l.position = p;
    l.intensity = intensity;
    return l;
  };
  s.lights.push_back(point({2.6f, 1.4f, 1.2f}, {2.0f, 1.0f, 0.5f}));
  s.lights.push_back(point({-0.4f, 0.8f, 1.6f}, {0.3f, 0.6f, 1.2f}));
  s.lights.push_back(point({1.0f, 2.6f, 0.4f}, {0.05f, 0.05f, 0.05f}));  // dim: rarely chosen
  auto grid = test::makeNoiseGrid(40, 1.0 / 20, 2);
  RestirOptions o;  // temporal + spatial
  o.radius = 6;
  RunSpec spec;
  spec.framesPerRun = 3;
  RestirRun run = runRestir(ctx(), compiler(), s, o, spec, [&](int) { return grid; });
  expectMatches(run, reference(s, grid, 512), "many_lights");
}

// The scene with its camera moved to `position` by `frame` (a key; the base pose before it).
Scene movedBy(Scene s, int frame, glm::vec3 position) {
  CameraKey key;
  key.frame = frame;
  key.pose = s.camera.base;
  key.pose.position = position;
  s.camera.keys.push_back(key);
  return s;
}

// ReSTIR over four frames whose camera moves to a new pose by the last one, against the
// reference of that pose.
void expectMovingCameraMatches(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const RestirOptions& o,
                               const char* label) {
  const Scene s = movedBy(baseScene(16), 4, {1.6f, 1.3f, 3.4f});
  auto grid = test::makeNoiseGrid(40, 1.0 / 20, 2);
  RunSpec spec;
  spec.framesPerRun = 4;
  RestirRun run = runRestir(ctx, compiler, s, o, spec, [&](int) { return grid; });
  expectMatches(run, reference(s, grid, 512, 4), label);
}

TEST_F(GpuRestir, MovingCameraMatchesReferencesOfItsPoses) {
  RestirOptions o;
  o.radius = 6;
  o.historyCapMoving = 5;  // a short moving history (the bundled city sets 3; GpuRestirSurfaces' moving test keeps 8)
  expectMovingCameraMatches(ctx(), compiler(), o, "temporal_moving");
}

// The targets' colour weights (restir/colour.glsl, render.restir_target colour, the default):
// each pixel's target weighs the channels by the inverse of its colour as walks of its own
// estimate it, and the weights change only in frames where the general temporal pipeline runs.
// Under an orange sun and a blue sky (pixels of very different colours), over frames whose camera
// moves (the weights change in the 4th frame after the first, while it moves: the history's domain
// keeps its own) and then stands still (they change once more, at the first still frame, then
// stay: the same-domain pipeline), the image must match the reference of the last pose; and it
// must differ from the luminance target's in most lit pixels, with the same random numbers (the
// weights act: grey weights give the luminance's image bit for bit, both being dot(k, f)).
TEST_F(GpuRestir, ColourTargetUnderColouredLightsMatchesReference) {
  Scene s = movedBy(baseScene(16), 6, {1.6f, 1.3f, 3.4f});
  s.lights = {test::sunLight({0.4f, 1.0f, 0.3f}, {4.0f, 1.6f, 0.3f}), test::skyLight({0.04f, 0.10f, 0.45f})};
  s.render.maxBounces = 2;
  auto grid = test::makeNoiseGrid(40, 1.0 / 20, 2);
  RestirOptions colour;
  colour.radius = 6;
  colour.historyCapMoving = 5;
  RestirOptions luminance = colour;
  luminance.colourTarget = false;
  RunSpec spec;
  // Weights change in frames 1 (grey), 5 (moving: frames 2-6 move) and 7 (the first still frame).
  spec.framesPerRun = 7;
  RestirRun run = runRestir(ctx(), compiler(), s, colour, spec, [&](int) { return grid; });
  expectMatches(run, reference(s, grid, 512, 7), "colour_target");
  // Weights that change in every moving frame (frames 2-5 move), between two fixed sets far apart
  // (RestirOptions::colourAlternate): each frame's history's domain must be evaluated with the
  // history's weights (notes/session-39-closing-note.md has what the current ones read).
  Scene m = s;
  m.camera.keys.back().frame = 5;
  RunSpec moving = spec;
  moving.framesPerRun = 5;
  RestirOptions everyFrame = colour;
  everyFrame.colourMovingInterval = 1;
  everyFrame.colourAlternate = true;
  RestirRun runMoving = runRestir(ctx(), compiler(), m, everyFrame, moving, [&](int) { return grid; });
  expectMatches(runMoving, reference(m, grid, 512, 5), "colour_target_moving");
  RunSpec two = spec;
  two.runs = 2;
  const Image a = runRestir(ctx(), compiler(), s, colour, two, [&](int) { return grid; }).mean;
  const Image b = runRestir(ctx(), compiler(), s, luminance, two, [&](int) { return grid; }).mean;
  size_t lit = 0, differ = 0;
  for (size_t i = 0; i + 2 < a.rgb.size(); i += 3) {
    if (!(b.rgb[i] + b.rgb[i + 1] + b.rgb[i + 2] > 0.0f)) continue;
    ++lit;
    differ += a.rgb[i] != b.rgb[i] || a.rgb[i + 1] != b.rgb[i + 1] || a.rgb[i + 2] != b.rgb[i + 2] ? 1 : 0;
  }
  std::printf("[restir] colour target: %zu of %zu lit pixels differ from the luminance target's\n", differ, lit);
  ASSERT_GT(lit, a.rgb.size() / 6) << "too few lit pixels to compare";
  EXPECT_GT(differ, lit / 2) << "the colour weights must change the targets";
}

// Pixels whose value differs between the two options' mean images (two runs of three frames
// over a noise cloud): under a still camera and under one that moves in the third frame.
struct DifferingPixels {
  size_t still;
  size_t moving;
  size_t pixels;
};

DifferingPixels differingPixels(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const RestirOptions& a,
                                const RestirOptions& b) {
  auto grid = test::makeNoiseGrid(40, 1.0 / 20, 2);
  RunSpec spec;
  spec.runs = 2;
  spec.framesPerRun = 3;
  auto differ = [&](const Scene& s) {
    const Image x = runRestir(ctx, compiler, s, a, spec, [&](int) { return grid; }).mean;
    const Image y = runRestir(ctx, compiler, s, b, spec, [&](int) { return grid; }).mean;
    size_t n = 0;
    for (size_t i = 0; i + 2 < x.rgb.size(); i += 3) {
      n += x.rgb[i] != y.rgb[i] || x.rgb[i + 1] != y.rgb[i + 1] || x.rgb[i + 2] != y.rgb[i + 2] ? 1 : 0;
    }
    return n;
  };
  const Scene still = baseScene(16);
  const Scene moving = movedBy(still, 3, {1.3f, 1.3f, 3.5f});
  return {differ(still), differ(moving), size_t(still.camera.width) * size_t(still.camera.height)};
}

// restir_history_cap_moving caps the history only in frames whose camera moved: with a still
// camera the two caps give the same image to the bit, with a moving one different images (the
// Z-test above runs with 20 still and 5 moving).
TEST_F(GpuRestir, HistoryCapWhileMovingActsOnlyWhenTheCameraMoves) {
  RestirOptions tight;
  tight.radius = 6;
  tight.historyCap = 20;
  tight.historyCapMoving = 2;
  RestirOptions loose = tight;
  loose.historyCapMoving = 20;
  const DifferingPixels d = differingPixels(ctx(), compiler(), tight, loose);
  EXPECT_EQ(d.still, 0u) << "a still camera must keep restir_history_cap";
  EXPECT_GT(d.moving, d.pixels / 4u) << "a moving camera's history must be capped by restir_history_cap_moving";
}

// A still camera over an unchanged grid dispatches the temporal pipeline compiled for one domain
// (PLUME_RS_SAME_DOMAIN: the identity shift and the stored targets, no target code; restir/
// reuse.glsl). It must give the general pipeline's image to rounding, which also checks that the
// target the general one evaluates is the one the candidates stored (the same function, p̂ of
// each path in its own pixel); and that image must differ from one without temporal reuse (the
// history is used at all).
TEST_F(GpuRestir, SameDomainTemporalPipelineMatchesTheGeneralOne) {
  RestirOptions same;
  same.radius = 6;
  RestirOptions general = same;
  general.sameDomainTemporal = false;
  RestirOptions none = same;
  none.historyCap = 0;
  auto grid = test::makeNoiseGrid(40, 1.0 / 20, 2);
  RunSpec spec;
  spec.runs = 2;
  spec.framesPerRun = 4;
  const Scene s = baseScene(16);
  auto meanOf = [&](const RestirOptions& o) { return runRestir(ctx(), compiler(), s, o, spec, [&](int) { return grid; }).mean; };
  const Image a = meanOf(same), b = meanOf(general), c = meanOf(none);
  const auto [worst, lit] = test::relativeAgreement(a, b);
  size_t differ = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i) differ += b.rgb[i] > 0.0f && a.rgb[i] != c.rgb[i] ? 1 : 0;
  std::printf("[restir] same-domain temporal: worst relative difference %.3g over %zu lit channels, %zu differ "
              "from no temporal reuse\n", worst, lit, differ);
  ASSERT_GT(lit, a.rgb.size() / 2) << "too few lit channels to compare";
  EXPECT_LT(worst, 1e-5) << "the same-domain temporal pipeline must equal the general one to rounding";
  EXPECT_GT(differ, lit / 2) << "temporal reuse must change the image (the history is used)";
}

// The pixels whose camera rays miss the volume run through the passes' variants without walks
// (PLUME_RS_OUTSIDE; render/pixel_order.h), the others through the walking pipelines: the frames
// must be those of the walking pipelines over every pixel, bit for bit — a still and a moving
// camera, an animated grid (the history's volume differs), the generalised balance heuristic, and
// final shading's tail — and the split must be real (pixels on both sides).
TEST_F(GpuRestir, PixelsThatMissTheVolumeSkipTheWalksAndKeepTheImage) {
  Scene still = baseScene(24);
  still.camera.base.position = {1.0f, 1.2f, 7.5f};  // the grid's box covers part of the image
  const Scene moving = movedBy(still, 4, {2.4f, 1.6f, 7.0f});
  auto gridAt = [](int frame) { return test::makeNoiseGrid(40, 1.0 / 20, unsigned(10 + frame)); };
  // Two blobs 60 voxels apart, side by side in view: the box's middle is empty bricks, which the
  // footprint's occupied cells leave out.
  auto sparseGrid = [](int) {
    auto grid = test::makeNoiseGrid(20, 1.0 / 20, 9);
    auto other = test::makeNoiseGrid(20, 1.0 / 20, 11);
    auto acc = grid->getAccessor();
    for (auto it = other->cbeginValueOn(); it; ++it) acc.setValue(it.getCoord() + openvdb::Coord(60, 4, 0), *it);
    return grid;
  };
  Scene sparseBase = still;
  sparseBase.camera.base.position = {2.0f, 0.7f, 6.5f};
  sparseBase.camera.base.lookAt = {2.0f, 0.6f, 0.5f};
  const Scene sparse = movedBy(sparseBase, 4, {2.6f, 1.0f, 6.3f});
  struct Case {
    const char* name;
    const Scene* scene;
    bool animated;
    int maxBounces;
    int prefix;
    uint32_t mis;
    bool sparse;
  };
  const Case cases[] = {{"still camera", &still, false, 1, 16, shared::RS_MIS_PAIRWISE, false},
                        {"moving camera", &moving, false, 1, 16, shared::RS_MIS_PAIRWISE, false},
                        {"moving camera, animated grid, tail", &moving, true, 3, 1, shared::RS_MIS_PAIRWISE, false},
                        {"moving camera, gbh", &moving, false, 2, 16, shared::RS_MIS_GBH, false},
                        {"moving camera, two blobs (empty bricks between)", &sparse, false, 2, 16,
                         shared::RS_MIS_PAIRWISE, true}};
  for (const Case& c : cases) {
    Scene s = *c.scene;
    s.render.maxBounces = c.maxBounces;
    std::vector<std::unique_ptr<GpuVolumeResources>> volumes;  // one per frame, or one for all
    for (int f = 1; f <= (c.animated ? 4 : 1); ++f) {
      volumes.push_back(std::make_unique<GpuVolumeResources>(ctx(), *bakeOf(c.sparse ? sparseGrid(f) : gridAt(f)),
                                                             s.media[0].densityScale));
    }
    auto frames = [&](bool cull) {
      RestirOptions o;
      o.radius = 6;
      o.mis = c.mis;
      o.prefix = c.prefix;
      o.cullOutside = cull;
      return restirFrames(ctx(), compiler(), s, o, volumes);
    };
    const std::vector<Image> culled = frames(true), walked = frames(false);
    const auto [differ, lit] = bitDifferences(walked, culled);
    // The split the last frame used: the frame's camera over its volume's box.
    const VolumeFootprint& footprint = volumes.back()->footprint();
    const PixelOrder order = volumePixelOrder(gpuCamera(s.camera, 4), s.camera.width, s.camera.height, footprint);
    VolumeFootprint box = footprint;
    box.cells.clear();
    const uint32_t boxInside = volumePixelOrder(gpuCamera(s.camera, 4), s.camera.width, s.camera.height, box).inside;
    std::printf("[restir] outside variants, %s: %u of %zu pixels may see the volume (%u by its box alone); %zu of "
                "%zu channels differ\n", c.name, order.inside, order.pixels.size(), boxInside, differ, lit);
    if (c.sparse) {
      EXPECT_LT(order.inside, boxInside * 9 / 10) << c.name << ": the empty bricks must take pixels away";
    }
    EXPECT_EQ(differ, 0u) << c.name << ": the outside variants must not change any pixel";
    EXPECT_GT(order.inside, order.pixels.size() / 10) << c.name;
    EXPECT_LT(order.inside, order.pixels.size() * 9 / 10) << c.name;
    EXPECT_GT(lit, culled.size() * culled[0].rgb.size() / 2) << c.name << ": too few lit channels";
  }
}

// The stored paths' vertices in a storage buffer (PLUME_RS_VERTEX_BUFFER: where a device's texel
// buffers cannot hold them and its storage buffers can, render/restir.cpp) give the frames of the
// texel buffer, bit for bit: a moving camera over an animated grid with final shading's tail past
// a prefix of two vertices, a still camera at 6 bounces, and walls with a fin (surfaces: the
// reconnection vertex keeps a triangle index in a float's bits).
TEST_F(GpuRestir, PathVerticesInAStorageBufferGiveTheSameFrames) {
  Scene volumeOnly = baseScene(24);
  volumeOnly.camera.base.position = {1.0f, 1.2f, 7.5f};
  const Scene moving = movedBy(volumeOnly, 4, {2.4f, 1.6f, 7.0f});
  const Scene walls = test::wallsAndFinScene(24, 3);
  struct Case {
    const char* name;
    const Scene* scene;
    bool animated;
    int maxBounces;
    int prefix;
  };
  const Case cases[] = {{"moving camera, animated grid, tail", &moving, true, 4, 2},
                        {"still camera, 6 bounces", &volumeOnly, false, 6, 16},
                        {"walls and fin, reconnection", &walls, false, 3, 16}};
  for (const Case& c : cases) {
    Scene s = *c.scene;
    s.render.maxBounces = c.maxBounces;
    std::vector<std::unique_ptr<GpuVolumeResources>> volumes;
    for (int f = 1; f <= (c.animated ? 4 : 1); ++f) {
      volumes.push_back(std::make_unique<GpuVolumeResources>(
          ctx(), *bakeOf(test::makeNoiseGrid(c.scene == &walls ? 32 : 40, 1.0 / 20, unsigned(10 + f))),
          s.media[0].densityScale));
    }
    auto frames = [&](bool inBuffer) {
      RestirOptions o;
      o.radius = 6;
      o.prefix = c.prefix;
      o.verticesInStorageBuffer = inBuffer;
      return restirFrames(ctx(), compiler(), s, o, volumes);
    };
    const std::vector<Image> texels = frames(false), buffer = frames(true);
    const auto [differ, lit] = bitDifferences(texels, buffer);
    std::printf("[restir] vertices in a storage buffer, %s: %zu of %zu lit channels differ\n", c.name, differ, lit);
    EXPECT_EQ(differ, 0u) << c.name << ": the vertices' storage must not change any pixel";
    EXPECT_GT(lit, texels.size() * texels[0].rgb.size() / 2) << c.name << ": too few lit channels";
  }
}

// restir_candidates_moving sets M only in frames whose camera moved since the previous frame:
// with a still camera the scene's M applies (the same image to the bit as without the setting),
// with a moving one the images differ. Unbiasedness with it is the Z-test below.
TEST_F(GpuRestir, CandidatesWhileMovingActOnlyWhenTheCameraMoves) {
  RestirOptions more;
  more.radius = 6;
  more.candidatesMoving = 8;
  RestirOptions plain = more;
  plain.candidatesMoving = 0;
  const DifferingPixels d = differingPixels(ctx(), compiler(), more, plain);
  EXPECT_EQ(d.still, 0u) << "a still camera must keep restir_candidates";
  EXPECT_GT(d.moving, d.pixels / 4u) << "a moving camera's frames must use restir_candidates_moving";
}

// With more candidates while moving, ReSTIR still converges to the reference of its last pose.
TEST_F(GpuRestir, CandidatesWhileMovingMatchReferenceOfTheLastPose) {
  RestirOptions o;
  o.radius = 6;
  o.historyCapMoving = 5;
  o.candidatesMoving = 8;  // moving frames M 8, still ones M 4 (the defaults' M)
  expectMovingCameraMatches(ctx(), compiler(), o, "temporal_moving_m8");
}

// restir_history_cap_static caps the history only in frames where neither the camera nor the grid
// changed: there a longer cap changes the image (from the third frame, whose history holds two
// frames' candidates: more than the plain cap's one), with a camera that moves from the second
// frame on (differingPixels) or a grid that changes every frame not a bit.
TEST_F(GpuRestir, StaticHistoryCapActsOnlyWhereNothingChanged) {
  RestirOptions capped;
  capped.radius = 6;
  capped.rounds = 0;
  capped.historyCap = 1;
  RestirOptions longer = capped;
  longer.historyCapStatic = 8;
  const DifferingPixels d = differingPixels(ctx(), compiler(), longer, capped);
  const Scene s = baseScene(16);
  const auto animated = noiseVolumes(ctx(), s, {11, 12, 13, 14});
  const auto [differAnimated, lit] = bitDifferences(restirFrames(ctx(), compiler(), s, longer, animated),
                                                    restirFrames(ctx(), compiler(), s, capped, animated));
  std::printf("[restir] restir_history_cap_static 8 against 0 (cap 1): %zu of %zu pixels differ still, %zu with the "
              "camera moving, %zu of %zu lit channels over an animated grid\n", d.still, d.pixels, d.moving,
              differAnimated, lit);
  EXPECT_GT(d.still, d.pixels / 4u) << "a still camera over a still grid must use restir_history_cap_static";
  EXPECT_EQ(d.moving, 0u) << "a moving camera's frames must keep restir_history_cap(_moving)";
  EXPECT_EQ(differAnimated, 0u) << "frames whose grid changed must keep restir_history_cap";
  EXPECT_GT(lit, size_t(4 * 3 * 16 * 16) / 2) << "too few lit channels";
}

// A long static history converges to the reference: a still camera without spatial reuse where
// nothing changes (restir_rounds_static 0), its history capped at 2 x M where anything changes
// but at 64 x M here, 8 frames per run (the history holds up to 7 frames' candidates, past the
// plain cap from the fourth frame on).
TEST_F(GpuRestir, LongStaticHistoryMatchesReference) {
  RestirOptions o;
  o.radius = 6;
  o.roundsStatic = 0;
  o.historyCap = 2;
  o.historyCapStatic = 64;
  expectStillCameraMatches(ctx(), compiler(), o, 8, "long_static_history");
}

// restir_rounds_static sets R only in frames where neither the camera nor the grid changed: over a
// still view the frames differ from the plain R's (from the second on: the first has no history),
// over a camera that moves every frame or a grid that changes every frame not a bit.
TEST_F(GpuRestir, StaticRoundsActOnlyWhereNothingChanged) {
  const Scene s = baseScene(16);
  Scene moving = s;
  for (int f = 1; f <= 4; ++f) {
    CameraKey key;
    key.frame = f;
    key.pose = s.camera.base;
    key.pose.position += glm::vec3(0.05f * float(f), 0.02f * float(f), 0.0f);
    moving.camera.keys.push_back(key);
  }
  const auto one = noiseVolumes(ctx(), s, {2}), animated = noiseVolumes(ctx(), s, {11, 12, 13, 14});
  RestirOptions set;
  set.radius = 6;
  set.roundsStatic = 0;  // R 1 elsewhere
  RestirOptions plain = set;
  plain.roundsStatic = -1;
  auto differ = [&](const Scene& scene, const std::vector<std::unique_ptr<GpuVolumeResources>>& volumes) {
    return bitDifferences(restirFrames(ctx(), compiler(), scene, set, volumes),
                          restirFrames(ctx(), compiler(), scene, plain, volumes));
  };
  const BitDifferences still = differ(s, one), camera = differ(moving, one), grid = differ(s, animated);
  std::printf("[restir] restir_rounds_static 0 against -1 (R 1): %zu of %zu lit channels differ over a still view, %zu "
              "of %zu with the camera moving, %zu of %zu over an animated grid\n", still.differ, still.lit,
              camera.differ, camera.lit, grid.differ, grid.lit);
  EXPECT_GT(still.differ, still.lit / 4) << "a still view must use restir_rounds_static";
  EXPECT_EQ(camera.differ, 0u) << "a moving camera's frames must keep restir_rounds";
  EXPECT_EQ(grid.differ, 0u) << "frames whose grid changed must keep restir_rounds";
  for (const BitDifferences* d : {&still, &camera, &grid}) EXPECT_GT(d->lit, size_t(4 * 3 * 16 * 16) / 2);
}

// A still view's long history without spatial reuse, then a camera that moves in the fourth frame
// (frames 2 and 3 static, under the static cap and rounds; the fourth under the plain ones, after a
// shift of that history): Z-test against the reference of the last pose. 1024 runs: heavy tails
// (the moving camera's Z-tests above read worst pixels of z -3.0 to -3.5 at 256 runs).
TEST_F(GpuRestir, StaticRecipeThenMovingCameraMatchesReferenceOfTheLastPose) {
  Scene s = baseScene(16);
  CameraKey hold;  // frames 1-3 at the base pose exactly (base at frame 1, this key at 3)
  hold.frame = 3;
  hold.pose = s.camera.base;
  CameraKey moved = hold;
  moved.frame = 4;
  moved.pose.position = {1.6f, 1.3f, 3.4f};
  s.camera.keys = {hold, moved};
  auto grid = test::makeNoiseGrid(40, 1.0 / 20, 2);
  RestirOptions o;
  o.radius = 6;
  o.historyCap = 1;
  o.historyCapMoving = 1;
  o.historyCapStatic = 20;
  o.roundsStatic = 0;
  RunSpec spec;
  spec.runs = 1024;
  spec.framesPerRun = 4;
  RestirRun run = runRestir(ctx(), compiler(), s, o, spec, [&](int) { return grid; });
  expectMatches(run, reference(s, grid, 512, 4), "static_recipe_then_moving");
}

TEST_F(GpuRestir, AnimatedGridMatchesReferenceOfItsLastFrame) {
  Scene s = baseScene(16);
  auto gridAt = [](int frame) { return test::makeNoiseGrid(40, 1.0 / 20, unsigned(10 + frame)); };
  RestirOptions o;
  o.radius = 6;
  RunSpec spec;
  spec.framesPerRun = 3;
  spec.animatedGrid = true;
  RestirRun run = runRestir(ctx(), compiler(), s, o, spec, gridAt);
  expectMatches(run, reference(s, gridAt(3), 512, 3), "animated_grid");
}

// restir-biased drops MIS: the estimate is biased where neighbours' supports differ. The test
// measures the bias against the reference and bounds it (it is not expected to be zero).
TEST_F(GpuRestir, BiasedModeReportsBoundedBias) {
  Scene s = baseScene(16);
  auto grid = test::makeNoiseGrid(40, 1.0 / 20, 2);
  RestirOptions o;
  o.radius = 6;
  o.mis = shared::RS_MIS_BIASED;
  RunSpec spec;
  spec.framesPerRun = 4;
  RestirRun run = runRestir(ctx(), compiler(), s, o, spec, [&](int) { return grid; });
  Image ref = reference(s, grid, 512);
  const test::ReferenceCheck check = test::checkAgainstReference(run.mean, ref, checkOptions(run));
  const glm::dvec3 ratio = check.aggregate.meanRatio(), z = check.aggregate.z;
  std::printf("[restir] restir-biased: measured bias: mean ratio %.4f %.4f %.4f (aggregate z %.1f %.1f %.1f), relMSE "
              "%.3g, %zu of %d pixels fail the Z-test (worst z %.2f)\n", ratio.x, ratio.y, ratio.z, z.x, z.y, z.z,
              check.pixels.relMse, check.pixels.failingPixels, check.pixels.width * check.pixels.height,
              check.pixels.worstZ);
  for (int c = 0; c < 3; ++c) {
    // The bias is a loss (energy lost where a neighbour's domain cannot produce the canonical
    // path, compounded through the temporal history): a gain is an error, tested at the
    // aggregate test's level.
    EXPECT_LT(z[c], check.aggregate.threshold) << "channel " << c << ": restir-biased gains energy\n"
                                               << check.summary();
    // How much loss is acceptable is a design bound, not a statistical tolerance (measured on
    // lavapipe: mean ratio ~0.87); it catches a blow-up, not the expected loss.
    EXPECT_GT(ratio[c], 0.75) << "channel " << c << "\n" << check.summary();
  }
  EXPECT_LT(check.pixels.relMse, 0.05);
  EXPECT_EQ(run.dropped, 0u);
  EXPECT_EQ(run.truncated, 0u);
}

// --- Environment maps (DESIGN §2): the map's light samples are directions drawn from its texels'
// distribution (shaders/light/light.glsl), reused and reconnected like any direction sample;
// final shading reads the map for escaping camera rays.

namespace {
Light skyMapLight(glm::vec3 up, float rotateYDeg, float scale) {
  Light l = test::skyLight(glm::vec3(0));
  l.map = test::sourcePath("volumes/sky/sky.exr");
  l.up = up;
  l.rotateYDeg = rotateYDeg;
  l.scale = scale;
  return l;
}
}  // namespace

// The reference takes 4096 samples: at 1024 a few edge pixels, where the map's bright texels are
// rare and large contributions, read low in the reference, and the per-pixel test failed there
// against the unchanged shaders too at 4x the runs (worst pixel z 7.1 and 4.3 for two reference
// seeds; session 15: a first form of the lamp candidates, with other draws, met it at the
// default runs, z 4.5).
TEST_F(GpuRestir, SkyMapWithReuseMatchesReference) {
  Scene s = baseScene(16);
  s.lights = {skyMapLight({0, 1, 0}, 0.0f, 1.0f)};
  auto grid = test::makeNoiseGrid(40, 1.0 / 20, 2);
  RestirOptions o;  // temporal + spatial
  o.radius = 6;
  RunSpec spec;
  spec.framesPerRun = 3;
  RestirRun run = runRestir(ctx(), compiler(), s, o, spec, [&](int) { return grid; });
  expectMatches(run, reference(s, grid, 4096), "sky_map");
}

TEST_F(GpuRestir, RotatedSkyMapAndSunMatchReference) {
  Scene s = baseScene(16);
  s.lights = {skyMapLight({0.3f, 0.2f, 1.0f}, 140.0f, 1.5f), test::sunLight({-0.4f, 1.0f, 0.2f}, {1.0f, 0.9f, 0.8f})};
  s.render.maxBounces = 2;
  auto grid = test::makeNoiseGrid(40, 1.0 / 20, 3);
  RestirOptions o = noReuse();
  o.rounds = 1;
  o.radius = 6;
  RunSpec spec;
  RestirRun run = runRestir(ctx(), compiler(), s, o, spec, [&](int) { return grid; });
  expectMatches(run, reference(s, grid, 1024), "rotated_sky_map");
}

// --- Any path length (issue 13): reservoirs hold paths of at most K vertices (render.restir_prefix),
// final shading path-traces the longer ones (the tail, restir/shade.glsl). A small dense cloud of
// albedo 0.98, K = 4: paths of more than 4 vertices carry a large share of the image.

Scene longPathScene(int bounces) {
  Scene s = baseScene(12);
  s.media[0].densityScale = 25.0f;
  s.media[0].albedo = glm::vec3(0.98f);
  s.render.maxBounces = bounces;
  return s;
}

openvdb::FloatGrid::Ptr longPathGrid() { return test::makeNoiseGrid(32, 1.0 / 16, 5); }

RestirOptions longPathOptions(uint32_t mis) {
  RestirOptions o = noReuse();
  o.rounds = 1;
  o.radius = 2;
  o.prefix = 4;
  o.mis = mis;
  return o;
}

TEST_F(GpuRestir, LongPathsPairwise64BouncesMatchReference) {
  Scene s = longPathScene(64);
  auto grid = longPathGrid();
  RunSpec spec;
  spec.runs = 128;
  RestirRun run = runRestir(ctx(), compiler(), s, longPathOptions(shared::RS_MIS_PAIRWISE), spec,
                            [&](int) { return grid; });
  expectMatches(run, reference(s, grid, 512), "long_pairwise_64");
}

TEST_F(GpuRestir, LongPathsGbh256BouncesMatchReference) {
  Scene s = longPathScene(256);
  auto grid = longPathGrid();
  RunSpec spec;
  spec.runs = 128;
  RestirRun run = runRestir(ctx(), compiler(), s, longPathOptions(shared::RS_MIS_GBH), spec,
                            [&](int) { return grid; });
  expectMatches(run, reference(s, grid, 512), "long_gbh_256");
}

// The tail is needed and counted once: on this scene the paths of more than K vertices are a
// share of the image that the aggregate test resolves (the reference at K bounces fails against
// the reference at 64), so a ReSTIR image without the tail (the K-bounce image) or with it twice
// (64-bounce image + the same share again) fails where the one with it passes.
TEST_F(GpuRestir, PrefixAndTailCountEveryPathLengthOnce) {
  Scene s = longPathScene(64);
  auto grid = longPathGrid();
  const Image full = reference(s, grid, 512);
  Scene prefixOnly = s;
  prefixOnly.render.maxBounces = 4;
  const Image prefix = reference(prefixOnly, grid, 512);
  const test::ReferenceCheck dropped = test::checkAgainstReference(prefix, full);
  EXPECT_FALSE(dropped.aggregate.pass) << "the tail's share is too small to test: " << dropped.summary();
  const glm::dvec3 share = 1.0 - dropped.aggregate.meanRatio();
  std::printf("[restir] share of paths longer than 4 vertices: %.1f%% %.1f%% %.1f%%\n", 100 * share.x,
              100 * share.y, 100 * share.z);
  EXPECT_GT(share.x, 0.1);
}

TEST_F(GpuRestir, AcceptsAnyMaxBouncesWithFixedMemory) {
  Scene s = longPathScene(1024);
  s.camera.width = s.camera.height = 4;
  auto grid = longPathGrid();
  RestirOptions o;  // the defaults: K = 16, temporal + spatial
  RunSpec spec;
  spec.runs = 2;
  spec.framesPerRun = 2;
  RestirRun run = runRestir(ctx(), compiler(), s, o, spec, [&](int) { return grid; });
  for (float v : run.mean.rgb) EXPECT_TRUE(std::isfinite(v));
  EXPECT_EQ(run.dropped, 0u);
  EXPECT_EQ(run.truncated, 0u);
}

// An image whose per-pixel buffers exceed the device's limits is bad input: an InputError before
// anything is compiled or allocated, naming the buffer that allows the fewest pixels, that number
// and an image of the same aspect that fits every buffer (gpu::requirePerPixelStorage). ReSTIR's
// per-pixel arrays at 16 bounces: the accumulation (32 bytes, a storage buffer, which the viewer's
// display reads) and the pixel order (4 bytes); in storage texel buffers the paths' vertices (3 sets
// x 15 texels; in a storage buffer instead where only that holds them), the path heads with the
// passes' state (3 x 2 + 5 texels) and the reservoirs (3 texels). On lavapipe (128 MiB, 2^27
// texels) the vertices decide: 2.98 megapixels (1920x1080 renders; session 25: the accumulation
// with the state, 1.2 megapixels; session 24: 0.19). The size is made from this device's limits,
// so the test is the same on any device; the suggested image is checked against the limit it was
// made from. The texel buffers' check alone is called directly below.
TEST_F(GpuRestir, ImageTooLargeForTheDeviceIsAClearErrorBeforeCompiling) {
  Scene s = baseScene(8);
  s.render.maxBounces = 16;
  RestirOptions o;
  const double bytes = double(ctx().limits().maxStorageBufferRange);
  const double texelCount = double(ctx().limits().maxTexelBufferElements);
  struct Array {
    const char* name;
    double most;  // pixels
  };
  const bool verticesInTexels = texelCount * 16.0 >= bytes;  // the larger kind holds them
  const Array arrays[] = {{"accumulation (32 bytes a pixel)", bytes / 32.0},
                          {"pixel order (4 bytes a pixel)", bytes / 4.0},
                          {verticesInTexels ? "reservoir path vertices (45 texels a pixel)"
                                            : "reservoir path vertices (720 bytes a pixel)",
                           verticesInTexels ? texelCount / 45.0 : bytes / 720.0},
                          {"reservoir paths and pass state (11 texels a pixel)", texelCount / 11.0},
                          {"reservoirs (3 texels a pixel)", texelCount / 3.0}};
  const Array* fewest = &arrays[0];
  for (const Array& a : arrays) fewest = a.most < fewest->most ? &a : fewest;
  const double pixels = 1.5 * fewest->most;
  s.camera.width = int(std::ceil(std::sqrt(pixels * 16.0 / 9.0)));
  s.camera.height = int(std::ceil(std::sqrt(pixels * 9.0 / 16.0)));
  try {
    Restir restir(ctx(), compiler(), s, o);
    FAIL() << "a " << s.camera.width << "x" << s.camera.height << " image was accepted";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(std::string("for its ") + fewest->name), std::string::npos) << m;
    const size_t at = m.find("e.g. ");
    ASSERT_NE(at, std::string::npos) << m;
    int w = 0, h = 0;
    ASSERT_EQ(std::sscanf(m.c_str() + at, "e.g. %dx%d", &w, &h), 2) << m;
    EXPECT_LE(double(w) * h, fewest->most) << m;
    EXPECT_GT(double(w) * h, 0.98 * fewest->most) << m;
    EXPECT_NEAR(double(w) / h, 16.0 / 9.0, 0.01) << m;
  }
  gpu::PerPixelBuffers texels;
  texels.texels = {{"test texels", 1024}};
  const double texelLimit = double(ctx().limits().maxTexelBufferElements);
  const int side = int(std::ceil(std::sqrt(2.0 * texelLimit / 1024.0)));
  EXPECT_NO_THROW(gpu::requirePerPixelStorage(ctx(), "test", texels, side / 2, side / 2, "-"));
  try {
    gpu::requirePerPixelStorage(ctx(), "test", texels, side, side, "-");
    FAIL() << side << "x" << side << " at 1024 texels a pixel was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("test texels (1024 texels a pixel), more than the device's largest texel buffer"),
              std::string::npos) << e.what();
  }
  // Two arrays, the one that allows fewer pixels named, the image suggested within both.
  gpu::PerPixelBuffers two = texels;
  const double storageLimit = double(ctx().limits().maxStorageBufferRange);
  const size_t bytesPerPixel = size_t(std::ceil(storageLimit / (texelLimit / 1024.0) * 2.0));  // half the pixels
  two.storageBytes = {{"test bytes", bytesPerPixel}};
  try {
    gpu::requirePerPixelStorage(ctx(), "test", two, side, side, "-");
    FAIL() << side << "x" << side << " was accepted";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("test bytes ("), std::string::npos) << m;
    const size_t at = m.find("e.g. ");
    ASSERT_NE(at, std::string::npos) << m;
    int w = 0, h = 0;
    ASSERT_EQ(std::sscanf(m.c_str() + at, "e.g. %dx%d", &w, &h), 2) << m;
    EXPECT_LE(double(w) * h * 1024.0, texelLimit) << m;
    EXPECT_LE(double(w) * h * double(bytesPerPixel), storageLimit) << m;
  }
}

// The other side of the limits: an image within them renders. ReSTIR's per-pixel arrays are
// storage texel buffers, bounded by maxTexelBufferElements (lavapipe: 2^27 texels, 2 GiB) and not
// by the storage buffer range (128 MiB); from session 28 to 33 they were created as storage
// buffers too (for the path tracer's slots, which alone need it), and `plume render --mode restir`
// failed at 1280x720 ("reservoir paths and pass state needs 154.7 MiB, more than the device's
// storage buffer limit"). 1920x1080 at 4 bounces: its paths and pass state need 11 texels a pixel,
// 348 MiB; one frame renders, every pixel finite (with the flag back on every texel buffer it
// throws that error again).
TEST_F(GpuRestir, FullHdImageRendersWhereItsTexelArraysPassTheStorageBufferRange) {
  Scene s = baseScene(8);
  s.camera.width = 1920;
  s.camera.height = 1080;
  s.render.maxBounces = 4;
  const double pathBytes = (3.0 * 2.0 + 5.0) * 16.0 * 1920.0 * 1080.0;
  std::printf("[restir] 1920x1080: paths and pass state %.0f MiB; the device's storage buffer range %.0f MiB, "
              "texel buffers %u texels\n",
              pathBytes / 1048576.0, ctx().limits().maxStorageBufferRange / 1048576.0, ctx().limits().maxTexelBufferElements);
  if (pathBytes <= double(ctx().limits().maxStorageBufferRange)) {
    std::printf("[restir] (this device's storage buffers would hold them: the test shows nothing here)\n");
  }
  const auto volumes = noiseVolumes(ctx(), s, {3});
  Restir restir(ctx(), compiler(), s, RestirOptions{});
  restir.setVolumes(*volumes[0], *volumes[0]);
  const Image image = restir.renderFrame(1, 1);
  ASSERT_EQ(image.rgb.size(), size_t(3) * 1920 * 1080);
  size_t nonFinite = 0, lit = 0;
  for (float v : image.rgb) {
    nonFinite += std::isfinite(v) ? 0 : 1;
    lit += v > 0.0f ? 1 : 0;
  }
  EXPECT_EQ(nonFinite, 0u);
  EXPECT_GT(lit, image.rgb.size() / 10);
}
