// ReSTIR against the CPU reference on a scene built in code
// (tests/test_restir_surfaces*.cpp): independent one-frame runs of spatial
// reuse (support/extreme.h runRestirCase), the per-pixel and aggregate checks
// of support/reference_check.h, for each MIS kind asked for. Pixels the
// reference does not resolve (support/resolution.h: fewer than 100 expected
// first vertices on their camera rays) are left out of the per-pixel test.
#pragma once

#include "reference/reference.h"
#include "render/restir.h"
#include "support/extreme.h"
#include "support/reference_check.h"
#include "support/resolution.h"

#include <cstdio>
#include <string>
#include <vector>

namespace plume::test {

// The CPU reference of scene s at spp (seed 4242).
inline Image restirCheckReference(Scene s, openvdb::FloatGrid::Ptr grid,
                                  int spp, int frame = 1) {
  s.render.spp = spp;
  s.render.seed = 4242;
  ref::ReferenceOptions opt;
  opt.progress = false;
  opt.frame = frame;
  return ref::renderReference(s, grid, opt);
}

// One spatial round (k 2, radius 4), no history, MIS kind mis.
inline RestirOptions spatialReuse(uint32_t mis) {
  RestirOptions o;
  o.rounds = 1;
  o.radius = 4;
  o.historyCap = 0;
  o.mis = mis;
  return o;
}

// ReSTIR (pairwise and GBH, or only `misKinds`; `runs` independent runs each)
// against one reference of refSpp, with `base` (one spatial round by default;
// its prefix, shift and neighbour choice kept, its MIS kind replaced by each
// of misKinds), each run the last of framesPerRun frames (frames 1.. of the scene's camera; with
// previousGrid: the frames before the last render that grid, ExtremeCase::previousGrid).
inline void expectRestirMatchesReference(
    gpu::Context &ctx, gpu::ShaderCompiler &compiler, const Scene &s,
    openvdb::FloatGrid::Ptr grid, int runs, int refSpp, const std::string &name,
    std::vector<uint32_t> misKinds = {shared::RS_MIS_PAIRWISE,
                                      shared::RS_MIS_GBH},
    const RestirOptions &base = spatialReuse(shared::RS_MIS_PAIRWISE),
    int framesPerRun = 1, openvdb::FloatGrid::Ptr previousGrid = nullptr) {
  // A moving camera (s.camera.keys) is measured at the last frame's pose.
  const int refFrame = s.camera.keys.empty() ? 1 : framesPerRun;
  const Image ref = restirCheckReference(s, grid, refSpp, refFrame);
  const ResolutionMap resolution = referenceResolution(s, *grid, refSpp, refFrame);
  ExtremeCase c;
  c.name = name;
  c.scene = s;
  c.grid = grid;
  c.previousGrid = previousGrid;
  for (const uint32_t mis : misKinds) {
    const std::string label =
        name + (mis == shared::RS_MIS_GBH ? "_gbh" : "_pairwise") + (base.reconnect ? "" : "_copy");
    RestirOptions options = base;
    options.mis = mis;
    const EstimatorRun run = runRestirCase(ctx, compiler, c, runs, options, framesPerRun);
    ReferenceCheckOptions check;
    check.imageMeanVariance = run.imageMeanVariance;
    check.unresolved = resolution.unresolvedMask();
    check.outputGroup = "restir_surfaces";
    const ReferenceCheck result =
        expectMatchesReference(run.image, ref, label, check);
    EXPECT_EQ(run.truncated, 0u) << label;
    EXPECT_EQ(run.nonFinite, 0u) << label;
    std::printf("[restir surfaces] %s: %s (%.1f s)\n", label.c_str(),
                result.summary().c_str(), run.seconds);
  }
}

} // namespace plume::test
