// Helpers of the kernel counter tests (test_kernel_counters.cpp, test_kernel_counters_slow.cpp).
#pragma once

#include "media/bake.h"
#include "render/gpu_volume.h"
#include "scene/scene.h"

#include <openvdb/openvdb.h>

#include <cstdint>
#include <string>
#include <vector>

namespace plume::test {

// A camera on a unit box lit by a sun and a sky, 4 spp.
Scene smallScene(int size, int maxBounces);
BakedVolume bakeOf(openvdb::FloatGrid::Ptr grid);
// Makes scene s an emitting medium (albedo 0.5, colour emission from a noise grid) and returns
// the bake of its density and emission grids.
BakedVolume makeEmittingCase(Scene& s);
// The kernel counter words of a run (the counter buffer's words from KC_BASE on).
std::vector<uint32_t> kernelWords(const GpuVolumeResources& volume);
// The relations every tracker's block must satisfy:
//   lookups <= steps <= lookups + segments  (every step inside a segment looks the density up,
//                                             and each segment ends with at most one step past it)
//   active lanes per subgroup iteration in [1, 128] (8 on lavapipe)
//   no walks: no segments.
void expectPlausible(const std::vector<uint32_t>& words, const std::string& what);

namespace kc {
// VOL_TRACK_* of shaders/volume/walk.glsl
const uint32_t kDelta = 0, kRatio = 1, kResidual = 2, kDeltaEmit = 5, kRatioEmit = 6;
}  // namespace kc

}  // namespace plume::test
