// The kernel counters in ReSTIR's emitting passes (ratio tracking with emission in final shading,
// delta tracking with emission): bit-identical images with and without them, plausible counts
// (support/kernel_counters.h). Slow: two builds of ReSTIR's emitting passes (10-30 s on 2 cores).
#include "media/bake.h"
#include "media/vdb_loader.h"
#include "render/gpu_volume.h"
#include "render/restir.h"
#include "shaders/shared/kernel_counters.h"
#include "support/gpu_fixture.h"
#include "support/grids.h"
#include "support/kernel_counters.h"

#include <glm/glm.hpp>

using namespace plume;
namespace sh = plume::shared;

namespace {
class KernelCountersSlow : public test::GpuTest {};
}  // namespace

TEST_F(KernelCountersSlow, RestirEmittingMediumImageIsBitIdentical) {
  Scene s = test::smallScene(12, 3);
  const BakedVolume bake = test::makeEmittingCase(s);
  GpuVolumeResources volume(ctx(), bake, s.media[0].densityScale, &*s.media[0].emission);
  std::vector<uint32_t> words[2];
  Image images[2];
  for (int counters = 0; counters < 2; ++counters) {
    plume::Restir restir(ctx(), compiler(), s, RestirOptions{}, counters != 0);
    restir.setVolumes(volume, volume);
    volume.resetCounters();
    images[counters] = restir.renderFrame(1, 1);
    words[counters] = test::kernelWords(volume);
  }
  EXPECT_EQ(images[0].rgb, images[1].rgb);
  EXPECT_EQ(words[0], std::vector<uint32_t>(words[0].size(), 0u));
  test::expectPlausible(words[1], "restir, emission");
  EXPECT_GT(words[1][test::kc::kRatioEmit * sh::KC_PER_TRACKER + sh::KC_LOOKUPS], 0u);
}
