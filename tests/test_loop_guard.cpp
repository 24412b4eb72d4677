// The driver-loop-limit probe (shaders/volume/loop_guard.glsl): llvmpipe ends every loop of an
// invocation once 65535 loop iterations have run in it, silently. The probe must report exactly
// the invocations whose loops were cut, and nothing when none was (on any device).
#include "gpu/pipeline.h"
#include "media/vdb_loader.h"
#include "render/gpu_volume.h"
#include "shaders/shared/bindings.h"
#include "support/gpu_fixture.h"
#include "support/grids.h"

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

using namespace plume;

namespace {

class LoopGuard : public test::GpuTest {
 protected:
  struct Run {
    std::vector<uint32_t> counted;  // the loop's iterations per invocation
    uint32_t reported = 0;          // invocations the probe reported as cut
  };

  Run run(uint32_t iterations) {
    LoadedGrid loaded;
    loaded.grid = test::makeNoiseGrid(8, 0.1);
    const BakedVolume bake = bakeVolume(loaded);
    GpuVolumeResources volume(ctx(), bake, 1.0f);
    gpu::ComputePass pass(ctx(), compiler().compile("tests/loop_guard_kernel.comp", {}),
                          gpu::bindingTable(shared::BIND_VOLUME_COUNTERS + 2, GpuVolumeResources::bindingTypes(false, false)),
                          8, "loop guard", glm::uvec3(64, 1, 1));
    volume.bind(pass.set);
    const uint32_t n = 64;
    gpu::Buffer out(ctx(), n * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "counted");
    pass.set.bind(shared::BIND_VOLUME_COUNTERS + 1, out);
    const uint32_t push[2] = {iterations, 2u};
    ctx().submitAndWait([&](VkCommandBuffer cmd) { pass.record(cmd, glm::uvec3(n, 1, 1), push); });
    Run r;
    r.counted.resize(n);
    out.download(r.counted.data(), n * 4);
    r.reported = volume.loopLimitCount();
    return r;
  }
};

}  // namespace

TEST_F(LoopGuard, ReportsNothingWhenEveryLoopRanToTheEnd) {
  const Run r = run(1000);
  for (uint32_t c : r.counted) EXPECT_EQ(c, 1000u);
  EXPECT_EQ(r.reported, 0u);
}

// 70000 iterations in one loop exceed llvmpipe's budget: there the loop stops short and the probe
// reports every invocation; on a device without such a limit the loop runs to the end and the
// probe reports nothing. Either way the report matches what happened.
TEST_F(LoopGuard, ReportsExactlyTheInvocationsWhoseLoopsWereCut) {
  const Run r = run(70000);
  const uint32_t cut = uint32_t(std::count_if(r.counted.begin(), r.counted.end(), [](uint32_t c) { return c != 70000u; }));
  EXPECT_EQ(r.reported, cut);
  std::printf("[loop guard] %s: a 70000-iteration loop ran %u iterations, %u of %zu invocations reported\n",
              ctx().deviceName().c_str(), r.counted[0], r.reported, r.counted.size());
  if (ctx().deviceName().find("llvmpipe") != std::string::npos) {
    EXPECT_EQ(cut, r.counted.size()) << "llvmpipe no longer cuts a 70000-iteration loop: revisit volume/loop_guard.glsl";
    for (uint32_t c : r.counted) EXPECT_LT(c, 70000u);
  }
}
