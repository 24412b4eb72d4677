// The kernel benchmark (`plume bench --kernels`, issue 11): what the hot loops cost on the
// current Vulkan device and in the CPU reference, side by side, on one frame's grid held still.
//
// Time: the marginal milliseconds per image-wide sample (one more sample in every pixel) of the
// path tracer, of one ReSTIR iteration and of the CPU reference — wall time of k samples
// (iterations) for a few k, alternating methods and k over several rounds, and the Theil-Sen slope
// (median of pairwise slopes, robust on a loaded machine) of time over k, so that fixed costs (a
// dispatch, clearing the accumulation, the reference's set-up) fall into the intercept.
// Events: tracking steps, density lookups and DDA segments per image-wide sample, counted by a
// second build of each estimator's shaders with PLUME_KERNEL_COUNTERS (shared/kernel_counters.h;
// the timed build has none of it, and both draw the same random numbers) and by the reference's
// own counters (reference/counters.h); per second = per sample / the timed marginal cost. On the
// device also the active lanes per subgroup in the tracking loop, the transmittance loops and
// the DDA (lanes / subgroup iterations).
#pragma once

#include "gpu/context.h"
#include "gpu/shader_compiler.h"
#include "scene/scene.h"

#include <cstdint>
#include <string>
#include <vector>

namespace plume {

struct KernelBenchOptions {
  int gridFrame = -1;             // the animation frame whose grid is held still (-1: the scene's first)
  std::vector<int> spp{1, 2, 4, 8};  // the k of time(k): samples (ReSTIR: iterations) per run
  int rounds = 5;                 // alternating rounds (the fit uses every run; the table shows medians per k)
  int countSpp = 2;               // samples (iterations) of the counting runs, one dispatch each
  bool restir = true;             // time and count one ReSTIR iteration (the scene's settings)
  bool reference = true;          // the CPU reference
  std::string outDir;             // the markdown file (default: bench_out next to the scene)
  std::string commandLine;        // written into the markdown
};

// Events of one kind of loop per image-wide sample, and its lane occupancy on the device.
struct KernelLoop {
  std::string name;       // e.g. "delta tracking", "ratio tracking (NEE)"
  double walks = 0, segments = 0, steps = 0, lookups = 0;  // per image-wide sample
  double segmentLanes = 0, stepLanes = 0, lookupLanes = 0;  // active lanes per subgroup iteration (0: CPU)
};

struct KernelRow {
  std::string method;      // "path tracer", "ReSTIR iteration", "CPU reference"
  double msPerSample = 0;  // the slope: marginal ms per image-wide sample (iteration)
  double msPerSampleLow = 0, msPerSampleHigh = 0;  // quartiles of the pairwise slopes (the spread)
  double fixedMs = 0;      // the intercept
  std::vector<double> medianMs;  // per k of KernelBenchOptions::spp
  std::vector<KernelLoop> loops;  // loops with events, by tracker
  KernelLoop total;        // all loops: events per image-wide sample; lanes: tracking, transmittance, DDA below
  double trackingLanes = 0, transmittanceLanes = 0, ddaLanes = 0, lookupLanes = 0;
  double perSecond(double perSample) const { return msPerSample > 0 ? perSample / (msPerSample * 1e-3) : 0; }
};

struct KernelBenchResult {
  std::string device;
  double pixels = 0;  // per image-wide sample / pixels = per pixel sample
  std::vector<KernelRow> rows;
  std::string markdown, mdPath;
  bool overflow = false;  // a device counter word passed 2^31 in one dispatch (counts unreliable)
};

KernelBenchResult runKernelBench(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const Scene& scene,
                                 const KernelBenchOptions& options);

// The summary table (markdown) of a result, also printed by the command.
std::string kernelTable(const KernelBenchResult& r);

}  // namespace plume
