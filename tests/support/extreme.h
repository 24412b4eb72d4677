// The extreme-media suite (issue 13): scenes that stress every estimator — scale invariance,
// dense and bright, strongly forward/backward scattering against the light, grid values from
// 1e-30 to 1e30 with NaN/Inf/negative voxels, the camera inside a dense medium, a single voxel in
// empty space, an empty grid — and one runner per estimator (CPU reference, GPU path tracer,
// GPU ReSTIR) that reports what the suite's table needs: the image (mean and variance of the
// mean), wall time, truncated tracking loops and non-finite values. Used by
// tests/test_extreme_suite.cpp (small, in CI) and tests/test_extreme_suite_slow.cpp (larger,
// writes the table of notes/bench/extreme.md).
#pragma once

#include "core/image.h"
#include "gpu/context.h"
#include "gpu/shader_compiler.h"
#include "render/restir.h"
#include "scene/scene.h"

#include <openvdb/openvdb.h>

#include <string>
#include <vector>

namespace plume::test {

struct ExtremeCase {
  std::string name;
  Scene scene;
  openvdb::FloatGrid::Ptr grid;  // sanitised and clamped (media/vdb_loader.h)
  // What the reference renders: the case itself, or for scale invariance the original smoke
  // (the GPU renders of the rescaled grid must match the original's reference).
  Scene referenceScene;
  openvdb::FloatGrid::Ptr referenceGrid;
  uint64_t replaced = 0, clamped = 0;  // by sanitizeGrid and clampOpticalDepth
  bool restir = true;                  // ReSTIR renders the case
  bool mediumInView = true;            // the medium covers a good part of the image
  // ReSTIR over several frames (runRestirCase's framesPerRun > 1) only: when set, every frame
  // but the last renders this grid, and the last one `grid` with this as the previous frame's
  // volume (an animated grid under a still camera: the history's target is another volume's).
  openvdb::FloatGrid::Ptr previousGrid;
};

struct ExtremeSize {
  int pixels = 16;      // image width and height
  int bounces = 256;    // max_bounces of the dense-and-bright case
};

// Every case of the suite, built in code with fixed seeds.
std::vector<ExtremeCase> extremeCases(const ExtremeSize& size);

struct EstimatorRun {
  Image image;          // mean, with the variance of the mean per pixel
  double seconds = 0;   // wall time of the render (bake and shader variants included)
  // Tracking loops stopped by a step cap, and for ReSTIR also reservoirs dropped for non-finite
  // weights: any is a failure.
  uint64_t truncated = 0;
  uint64_t nonFinite = 0;  // non-finite values in the mean image
  // ReSTIR with spatial reuse correlates pixels: the variance of the image mean over pixels,
  // measured across independent runs (support/reference_check.h); unset for independent pixels.
  bool hasImageMeanVariance = false;
  glm::dvec3 imageMeanVariance{0.0};
};

EstimatorRun runReferenceCase(const ExtremeCase& c, int spp, uint32_t seed = 99);
EstimatorRun runPtCase(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const ExtremeCase& c, int spp);
// ReSTIR (pairwise MIS by default) as `runs` independent one-frame runs with spatial reuse
// (radius 2, one round, no history), so that per-pixel variances are honest.
EstimatorRun runRestirCase(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const ExtremeCase& c, int runs,
                           uint32_t mis);
// The same with any options (each run framesPerRun frames of the still scene from a reset
// history, the last one measured; ExtremeCase::previousGrid for an animated grid).
EstimatorRun runRestirCase(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const ExtremeCase& c, int runs,
                           const RestirOptions& options, int framesPerRun = 1);

uint64_t countNonFinite(const Image& image);

}  // namespace plume::test
