// plume bench SCENE: error against run time (DESIGN §6): path tracer vs ReSTIR variants at equal
// GPU time per frame, and the CPU reference beside them, static and moving camera; markdown table,
// CSV and SVG plot. `--kernels`: the kernel benchmark instead (bench/kernels.h).
#include "app/commands.h"
#include "app/settings_cli.h"
#include "core/error.h"
#include "core/log.h"
#include "bench/bench.h"
#include "bench/kernels.h"

#include <cstdio>
#include <fstream>
#include <iterator>
#include <memory>

namespace plume {
namespace {

struct BenchArgs {
  std::string scene, device, out;
  int width = 64, height = 64;
  BenchOptions options;
  SettingOverrides overrides;
  bool kernels = false, noCpuRef = false;
  KernelBenchOptions kernel;
};

// This process's command line (Linux), for the kernel table's notes; empty where unknown.
std::string commandLine() {
  std::ifstream in("/proc/self/cmdline", std::ios::binary);
  std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()), line;
  for (char c : all) line += c == '\0' ? ' ' : c;
  while (!line.empty() && line.back() == ' ') line.pop_back();
  return line;
}

int runBenchCommand(const BenchArgs& a) {
  Scene scene = loadScene(a.scene);
  // The kernel table's event counters cover the volume walks only (not the surfaces' traversal);
  // the error-against-time bench measures every estimator with surfaces.
  if (a.kernels && !scene.surfaces.empty()) {
    throw InputError(scene.path + ": surfaces: bench --kernels measures the volume walks only and takes no "
                     "surfaces: use plume bench without --kernels, or a scene without surfaces");
  }
  applyOverrides(scene.render, a.overrides);
  if (a.width > 0) scene.camera.width = a.width;
  if (a.height > 0) scene.camera.height = a.height;
  BenchOptions o = a.options;
  o.outDir = a.out;
  if (a.noCpuRef) o.cpuRefSpp.clear();
  gpu::Context ctx({a.device, false, true});
  gpu::ShaderCompiler compiler({}, gpu::ShaderCompiler::defaultCacheDir());
  if (a.kernels) {
    KernelBenchOptions k = a.kernel;
    k.gridFrame = a.options.gridFrame;
    k.outDir = a.out;
    k.commandLine = commandLine();
    const KernelBenchResult r = runKernelBench(ctx, compiler, scene, k);
    std::printf("%s\n%s\nwrote %s\n", r.device.c_str(), kernelTable(r).c_str(), r.mdPath.c_str());
    return kExitOk;
  }
  BenchResult r = runBench(ctx, compiler, scene, o);
  std::printf("%s\nwrote %s, %s, %s\n", r.markdown.c_str(), r.mdPath.c_str(), r.csvPath.c_str(), r.svgPath.c_str());
  return kExitOk;
}

}  // namespace

void addBenchCommand(CLI::App& app, Action& action) {
  auto args = std::make_shared<BenchArgs>();
  CLI::App* cmd = app.add_subcommand("bench", "relMSE against GPU time per frame: path tracer vs ReSTIR variants");
  cmd->add_option("scene", args->scene, "scene JSON file")->required();
  cmd->add_option("-o,--output", args->out, "folder for the table, CSV and SVG (default: bench_out next to the scene)");
  cmd->add_option("--width", args->width, "image width (default 64)")->check(CLI::Range(1, 16384));
  cmd->add_option("--height", args->height, "image height (default 64)")->check(CLI::Range(1, 16384));
  cmd->add_option("--warmup", args->options.warmup,
                  "frames before measuring (default: the ReSTIR variants' largest history cap c, at least 4: the "
                  "frames temporal reuse needs to reach steady state; the static camera's run counts "
                  "restir_history_cap_static too)")
      ->check(CLI::Range(0, 1000));
  cmd->add_option("--measure", args->options.frames, "measured frames")->check(CLI::Range(1, 1000));
  cmd->add_option("--frame", args->options.gridFrame, "animation frame whose grid is held still (default: the scene's first)")
      ->check(CLI::Range(0, 1 << 20));
  cmd->add_option("--ref-spp", args->options.refSpp, "samples per pixel of the cached reference")->check(CLI::Range(16, 1 << 24));
  cmd->add_option("--cpu-ref-spp", args->options.cpuRefSpp, "the CPU reference's rows: spp per frame (default 1 4 16)")
      ->check(CLI::Range(1, 1 << 20));
  cmd->add_flag("--no-cpu-ref", args->noCpuRef, "without the CPU reference's rows");
  cmd->add_option("--pt-spp", args->options.ptSpp, "path tracer spp per frame (its curve)");
  cmd->add_option("--only", args->options.only, "run only the ReSTIR variants whose name contains one of these strings");
  cmd->add_option("--camera", args->options.cameras, "camera runs: static, moving (default both)")
      ->check(CLI::IsMember({"static", "moving"}));
  cmd->add_flag("--save-images", args->options.saveImages, "also write each method's last measured frame and its reference (EXR)");
  cmd->add_option("--orbit", args->options.orbitDegPerFrame, "moving camera: degrees of orbit per frame");
  cmd->add_option("--device", args->device, "Vulkan device to use (substring of its name)");
  cmd->add_flag("--kernels", args->kernels,
                "kernel benchmark instead: marginal ms per image-wide sample, events per second and lane occupancy of "
                "the path tracer, one ReSTIR iteration and the CPU reference");
  cmd->add_option("--kernel-spp", args->kernel.spp, "--kernels: samples per run whose times give the slope (default 1 2 4 8)")
      ->check(CLI::Range(1, 4096));
  cmd->add_option("--kernel-rounds", args->kernel.rounds, "--kernels: alternating rounds (medians)")->check(CLI::Range(1, 100));
  cmd->add_option("--kernel-count-spp", args->kernel.countSpp, "--kernels: samples of the counting runs")
      ->check(CLI::Range(1, 4096));
  cmd->add_flag("!--no-restir", args->kernel.restir, "--kernels: without ReSTIR");
  cmd->add_flag("!--no-reference", args->kernel.reference, "--kernels: without the CPU reference");
  addSettingOptions(*cmd, args->overrides);
  cmd->callback([&action, args] { action = [args] { return runBenchCommand(*args); }; });
}

}  // namespace plume
