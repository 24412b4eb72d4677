// Error against run time (DESIGN §6; `plume bench`): the path tracer and ReSTIR variants on one
// device, in one process, alternating frame by frame, each frame's relMSE against a converged
// reference of that frame's camera pose (cached EXR next to the scene), after a warm-up.
// The path tracer runs at several spp, which gives its relMSE-against-time curve; each ReSTIR
// variant's equal-time gain is the ratio of that curve (log-log interpolation) to its relMSE.
// The CPU reference (src/reference, on the OpenVDB grid itself) runs beside them at several spp,
// timed by the wall clock, with its own seed (never the converged image's), so the three lie on
// one axis.
#pragma once

#include "gpu/context.h"
#include "gpu/shader_compiler.h"
#include "render/restir.h"
#include "scene/scene.h"

#include <string>
#include <vector>

namespace plume {

struct BenchOptions {
  // Frames before measuring, so that temporal reuse reaches steady state: -1 (the default) takes
  // the largest history cap c of the ReSTIR variants run (one iteration per frame adds M to a
  // history capped at c * M, so after c frames it is full), at least 4; with a still camera the
  // static cap too (restir_history_cap_static).
  int warmup = -1;
  int frames = 6;          // measured frames
  int gridFrame = -1;      // the animation frame whose grid is held still (-1: the scene's first)
  int refSpp = 2048;       // converged reference (GPU path tracer), >= 16x anything judged
  std::vector<int> ptSpp{1, 2, 4, 8, 16};
  std::vector<int> cpuRefSpp{1, 4, 16};  // the CPU reference's rows (empty: none)
  std::vector<std::pair<std::string, RestirOptions>> variants;  // empty: a default list
  std::vector<std::string> only;  // non-empty: ReSTIR variants whose name contains one of these
  std::vector<std::string> cameras{"static", "moving"};
  float orbitDegPerFrame = 1.0f;  // the moving-camera run orbits the look-at point
  std::string outDir;             // table, CSV, SVG
  bool saveImages = false;        // also each method's last measured frame (EXR) in outDir
};

struct BenchRow {
  std::string camera;  // "static" | "moving"
  std::string method;
  double frameMs = 0;  // median GPU time per frame (sum of pass timestamps); the CPU reference: wall time
  double relMse = 0;   // median over measured frames
  double ptRelMseAtEqualTime = 0;  // path tracer's curve at frameMs (ReSTIR and CPU reference rows)
  double gain = 0;                 // ptRelMseAtEqualTime / relMse
  bool outsidePtRange = false;     // frameMs outside the path tracer's measured times (extrapolated by 1/time)
  std::string passTimes;           // median per-pass ms
};

struct BenchResult {
  std::vector<BenchRow> rows;
  double referenceRelMse = 0;  // estimated from the reference's own variance (worst frame)
  int warmup = 0;              // frames rendered before measuring (BenchOptions::warmup resolved): static camera
  int warmupMoving = 0;        // ... moving camera
  std::string device;
  std::string markdown, csvPath, svgPath, mdPath;
};

BenchResult runBench(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const Scene& scene, const BenchOptions& options);

}  // namespace plume
