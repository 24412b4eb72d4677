// The kernel benchmark's counters (`plume bench --kernels`; shaders/shared/kernel_counters.h,
// reference/counters.h): compiled into the walk only on request, they change no pixel (the same
// random numbers, the same arithmetic: bit-identical images with and without them), a normal
// build writes none of them, and the counts obey what the walk implies:
//   lookups <= steps <= lookups + segments  (every step inside a segment looks the density up,
//                                             and each segment ends with at most one step past it)
//   active lanes per subgroup iteration in [1, subgroup size]
//   an empty grid: no tracking steps and no lookups.
#include "media/bake.h"
#include "media/vdb_loader.h"
#include "reference/counters.h"
#include "reference/reference.h"
#include "render/gpu_volume.h"
#include "render/path_tracer.h"
#include "render/restir.h"
#include "shaders/shared/kernel_counters.h"
#include "support/gpu_fixture.h"
#include "support/grids.h"
#include "support/scenes.h"

#include <glm/glm.hpp>

#include <string>
#include <vector>

using namespace plume;
namespace sh = plume::shared;

namespace {

Scene smallScene(int size, int maxBounces) {
  Scene s;
  s.path = "test-scene";
  s.camera.base.position = {0.5f, 0.6f, 2.2f};
  s.camera.base.lookAt = {0.5f, 0.5f, 0.5f};
  s.camera.base.fovY = 40.0f;
  s.camera.width = s.camera.height = size;
  Medium m;
  m.densityScale = 6.0f;
  s.media.push_back(m);
  s.lights = {test::sunLight({0.4f, 1.0f, 0.3f}, {3.0f, 2.8f, 2.5f}), test::skyLight({0.10f, 0.12f, 0.16f})};
  s.render.maxBounces = maxBounces;
  s.render.spp = 4;
  return s;
}

BakedVolume bakeOf(openvdb::FloatGrid::Ptr grid) {
  LoadedGrid loaded;
  loaded.grid = grid;
  loaded.name = "density";
  return bakeVolume(loaded);
}

// The kernel counter words of a run (the buffer's words from KC_BASE on).
std::vector<uint32_t> kernelWords(const GpuVolumeResources& volume) {
  std::vector<uint32_t> w = volume.counterWords();
  return std::vector<uint32_t>(w.begin() + sh::KC_BASE, w.end());
}

class KernelCounters : public test::GpuTest {
 protected:
  static Image renderPt(const Scene& s, GpuVolumeResources& volume, bool counters,
                        std::vector<uint32_t>* words = nullptr, std::string* variant = nullptr) {
    PathTracer tracer(ctx(), compiler(), s, counters);
    tracer.setVolume(volume);
    volume.resetCounters();
    tracer.beginFrame(1);
    tracer.addSamples(s.render.spp);
    if (words) *words = kernelWords(volume);
    if (variant) *variant = tracer.variantName();
    return tracer.readImage();
  }
};

// The relations every tracker's block must satisfy (see the top of the file).
void expectPlausible(const std::vector<uint32_t>& w, const std::string& what) {
  for (uint32_t t = 0; t < sh::KC_TRACKERS; ++t) {
    const uint32_t* c = &w[t * sh::KC_PER_TRACKER];
    SCOPED_TRACE(what + ", tracker " + std::to_string(t));
    EXPECT_LE(c[sh::KC_LOOKUPS], c[sh::KC_STEPS]);
    EXPECT_LE(c[sh::KC_STEPS], uint64_t(c[sh::KC_LOOKUPS]) + c[sh::KC_SEGMENTS]);
    // Lanes per subgroup iteration: at least one (an iteration is counted only with a lane
    // active) and at most the subgroup size (8 on lavapipe; no device has more than 128).
    for (auto [lanes, iters] : {std::pair{sh::KC_SEGMENTS, sh::KC_SEGMENT_ITERS}, std::pair{sh::KC_STEPS, sh::KC_STEP_ITERS},
                                std::pair{sh::KC_LOOKUPS, sh::KC_LOOKUP_ITERS}}) {
      EXPECT_LE(c[iters], c[lanes]);
      EXPECT_LE(c[lanes], 128ull * c[iters]);
    }
    if (c[sh::KC_WALKS] == 0) {
      EXPECT_EQ(c[sh::KC_SEGMENTS], 0u);
    }
  }
}

const uint32_t kDelta = 0, kRatio = 1, kResidual = 2;  // VOL_TRACK_* of shaders/volume/walk.glsl

}  // namespace

TEST_F(KernelCounters, PathTracerImageIsBitIdenticalAndCountsArePlausible) {
  const Scene s = smallScene(16, 4);
  GpuVolumeResources volume(ctx(), bakeOf(test::makeNoiseGrid(24, 1.0 / 24)), s.media[0].densityScale);
  std::vector<uint32_t> plain, counted;
  std::string plainVariant, countedVariant;
  const Image a = renderPt(s, volume, false, &plain, &plainVariant);
  const Image b = renderPt(s, volume, true, &counted, &countedVariant);
  EXPECT_NE(plainVariant, countedVariant);  // a variant of its own (its own SPIR-V in the cache)
  EXPECT_EQ(a.rgb, b.rgb);
  EXPECT_EQ(a.var, b.var);
  // A normal build counts nothing.
  EXPECT_EQ(plain, std::vector<uint32_t>(plain.size(), 0u));
  expectPlausible(counted, "path tracer");
  const uint32_t* delta = &counted[kDelta * sh::KC_PER_TRACKER];
  const uint32_t* ratio = &counted[kRatio * sh::KC_PER_TRACKER];
  EXPECT_GT(delta[sh::KC_WALKS], 0u);
  EXPECT_GT(delta[sh::KC_LOOKUPS], 0u);
  EXPECT_GT(ratio[sh::KC_WALKS], 0u);  // next-event estimation to the sun through the medium
  EXPECT_GT(ratio[sh::KC_LOOKUPS], 0u);
  // At most one camera walk per pixel sample and one per bounce after it.
  EXPECT_LE(delta[sh::KC_WALKS], uint32_t(16 * 16 * s.render.spp * (s.render.maxBounces + 1)));
}

TEST_F(KernelCounters, RestirImageIsBitIdenticalAndCountsArePlausible) {
  const Scene s = smallScene(16, 2);
  GpuVolumeResources volume(ctx(), bakeOf(test::makeNoiseGrid(24, 1.0 / 24)), s.media[0].densityScale);
  RestirOptions o;  // temporal and spatial reuse, pairwise MIS
  std::vector<uint32_t> words[2];
  Image images[2];
  for (int counters = 0; counters < 2; ++counters) {
    plume::Restir restir(ctx(), compiler(), s, o, counters != 0);
    restir.setVolumes(volume, volume);
    volume.resetCounters();
    for (int frame = 1; frame <= 3; ++frame) images[counters] = restir.renderFrame(frame, 1);
    words[counters] = kernelWords(volume);
  }
  EXPECT_EQ(images[0].rgb, images[1].rgb);
  EXPECT_EQ(words[0], std::vector<uint32_t>(words[0].size(), 0u));
  expectPlausible(words[1], "restir");
  EXPECT_GT(words[1][kResidual * sh::KC_PER_TRACKER + sh::KC_LOOKUPS], 0u);  // final shading's transmittance
}

TEST_F(KernelCounters, EmptyGridHasNoTrackingSteps) {
  const Scene s = smallScene(8, 3);
  openvdb::FloatGrid::Ptr grid = test::makeBoxGrid(16, 1.0 / 16, 0.0f);
  GpuVolumeResources volume(ctx(), bakeOf(grid), s.media[0].densityScale);
  std::vector<uint32_t> words;
  renderPt(s, volume, true, &words);
  for (uint32_t t = 0; t < sh::KC_TRACKERS; ++t) {
    EXPECT_EQ(words[t * sh::KC_PER_TRACKER + sh::KC_STEPS], 0u) << "tracker " << t;
    EXPECT_EQ(words[t * sh::KC_PER_TRACKER + sh::KC_LOOKUPS], 0u) << "tracker " << t;
  }

  ref::setKernelCounting(true);
  ref::ReferenceOptions opt;
  opt.progress = false;
  ref::renderReference(s, grid, opt);
  const ref::KernelCounts k = ref::kernelCounts();
  ref::setKernelCounting(false);
  EXPECT_EQ(k.collision.steps + k.transmittance.steps, 0u);
  EXPECT_EQ(k.collision.lookups + k.transmittance.lookups, 0u);
}

// The reference's own counters: only while counting, no change to its image, the same relations.
TEST(ReferenceKernelCounters, CountOnlyWhenAskedAndChangeNoPixel) {
  const Scene s = smallScene(12, 4);
  openvdb::FloatGrid::Ptr grid = test::makeNoiseGrid(24, 1.0 / 24);
  ref::ReferenceOptions opt;
  opt.progress = false;
  ref::setKernelCounting(true);
  ref::setKernelCounting(false);  // zeroed, then off
  const Image plain = ref::renderReference(s, grid, opt);
  const ref::KernelCounts none = ref::kernelCounts();
  EXPECT_EQ(none.collision.walks + none.transmittance.walks, 0u);
  ref::setKernelCounting(true);
  const Image counted = ref::renderReference(s, grid, opt);
  const ref::KernelCounts k = ref::kernelCounts();
  ref::setKernelCounting(false);
  EXPECT_EQ(plain.rgb, counted.rgb);
  for (const ref::WalkCounts& c : {k.collision, k.transmittance}) {
    EXPECT_GT(c.walks, 0u);
    EXPECT_GT(c.lookups, 0u);
    EXPECT_LE(c.lookups, c.steps);
    EXPECT_LE(c.steps, c.lookups + c.segments);
    EXPECT_GE(c.segments, c.walks);  // a walk that enters the grid's box crosses at least one cell
  }
  EXPECT_LE(k.collision.walks, uint64_t(12 * 12 * s.render.spp * (s.render.maxBounces + 1)));
}
