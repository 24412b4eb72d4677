#include "support/kernel_counters.h"

#include "media/vdb_loader.h"
#include "shaders/shared/kernel_counters.h"
#include "support/grids.h"
#include "support/scenes.h"

#include <gtest/gtest.h>

#include <utility>

namespace plume::test {

namespace sh = plume::shared;

BakedVolume makeEmittingCase(Scene& s) {
  s.media[0].albedo = glm::vec3(0.5f);
  Emission e;
  e.grid = "emission";
  e.scale = 2.0f;
  e.color = {1.0f, 0.5f, 0.25f};
  s.media[0].emission = e;
  LoadedGrid density, emission;
  density.grid = makeNoiseGrid(24, 1.0 / 24);
  density.name = "density";
  emission.grid = makeNoiseGrid(24, 1.0 / 24, 5);
  emission.name = "emission";
  BakedVolume bake = bakeVolume(density);
  bakeEmission(bake, density, emission);
  return bake;
}

Scene smallScene(int size, int maxBounces) {
  Scene s = test::sceneWithCamera("test-scene", {0.5f, 0.6f, 2.2f}, {0.5f, 0.5f, 0.5f}, size);
  Medium m;
  m.densityScale = 6.0f;
  s.media.push_back(m);
  s.lights = {sunLight({0.4f, 1.0f, 0.3f}, {3.0f, 2.8f, 2.5f}), skyLight({0.10f, 0.12f, 0.16f})};
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

std::vector<uint32_t> kernelWords(const GpuVolumeResources& volume) {
  std::vector<uint32_t> w = volume.counterWords();
  return std::vector<uint32_t>(w.begin() + sh::KC_BASE, w.end());
}

void expectPlausible(const std::vector<uint32_t>& w, const std::string& what) {
  for (uint32_t t = 0; t < sh::KC_TRACKERS; ++t) {
    const uint32_t* c = &w[t * sh::KC_PER_TRACKER];
    SCOPED_TRACE(what + ", tracker " + std::to_string(t));
    EXPECT_LE(c[sh::KC_LOOKUPS], c[sh::KC_STEPS]);
    EXPECT_LE(c[sh::KC_STEPS], uint64_t(c[sh::KC_LOOKUPS]) + c[sh::KC_SEGMENTS]);
    // An iteration is counted only with a lane active, so at least one lane per iteration.
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

}  // namespace plume::test
