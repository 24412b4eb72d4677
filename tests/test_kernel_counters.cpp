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
#include "support/kernel_counters.h"
#include "support/grids.h"
#include "support/scenes.h"

#include <glm/glm.hpp>

#include <string>
#include <vector>

using namespace plume;
namespace sh = plume::shared;
using test::bakeOf;
using test::expectPlausible;
using test::kernelWords;
using test::smallScene;
using namespace test::kc;

namespace {

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

// The emitting trackers are copies of the walk of their own: the same holds there (delta tracking
// with emission here; ReSTIR's ratio tracking with emission in test_kernel_counters_slow.cpp).
TEST_F(KernelCounters, EmittingMediumImagesAreBitIdentical) {
  Scene s = smallScene(12, 3);
  const BakedVolume bake = test::makeEmittingCase(s);
  GpuVolumeResources volume(ctx(), bake, s.media[0].densityScale, &*s.media[0].emission);
  std::vector<uint32_t> plain, counted;
  const Image a = renderPt(s, volume, false, &plain);
  const Image b = renderPt(s, volume, true, &counted);
  EXPECT_EQ(a.rgb, b.rgb);
  EXPECT_EQ(plain, std::vector<uint32_t>(plain.size(), 0u));
  expectPlausible(counted, "path tracer, emission");
  EXPECT_GT(counted[kDeltaEmit * sh::KC_PER_TRACKER + sh::KC_LOOKUPS], 0u);

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
