// plume render SCENE -o OUT.exr: the Vulkan renderer over frame sequences (DESIGN §4, §8).
#include "app/commands.h"
#include "app/frame_output.h"
#include "app/settings_cli.h"
#include "core/error.h"
#include "core/log.h"
#include "core/progress.h"
#include "gpu/context.h"
#include "gpu/shader_compiler.h"
#include "media/bake.h"
#include "media/vdb_loader.h"
#include "render/gpu_volume.h"
#include "render/path_tracer.h"
#include "scene/scene.h"

#include <chrono>
#include <memory>

namespace plume {
namespace {

struct RenderArgs {
  std::string scene;
  FrameOutputs outputs;
  bool quiet = false;
  int width = 0, height = 0;
  int batch = 4;
  std::string device;
  std::string texels = "float16";
  SettingOverrides overrides;
};

std::string passTimesText(const PassTimes& times) {
  std::string s;
  for (const auto& [name, ms] : times) s += strf("%s%s %.2f ms", s.empty() ? "" : ", ", name.c_str(), ms);
  return s;
}

int runRender(const RenderArgs& a) {
  setQuiet(a.quiet);
  Scene scene = loadScene(a.scene);
  applyOverrides(scene.render, a.overrides);
  if (a.width > 0) scene.camera.width = a.width;
  if (a.height > 0) scene.camera.height = a.height;
  const RenderSettings& rs = scene.render;
  if (rs.mode != "pt") {
    throw InputError(scene.path + ": render.mode: \"" + rs.mode + "\" is not implemented yet; use \"pt\"");
  }
  a.outputs.check(rs);
  BakeOptions bakeOptions;
  bakeOptions.format = a.texels == "float32" ? TexelFormat::Float32 : TexelFormat::Float16;

  gpu::Context ctx({a.device, false, !a.quiet});
  gpu::ShaderCompiler compiler({}, gpu::ShaderCompiler::defaultCacheDir());
  PathTracer tracer(ctx, compiler, scene);
  const Medium& medium = scene.media.at(0);
  const int frames = rs.frameLast - rs.frameFirst + 1;
  std::unique_ptr<ProgressBar> bar;
  if (!a.quiet) bar = std::make_unique<ProgressBar>("render", uint64_t(frames) * uint64_t(rs.spp));
  for (int frame = rs.frameFirst; frame <= rs.frameLast; ++frame) {
    if (a.outputs.skip(frame, rs)) {
      if (bar) bar->advance(uint64_t(rs.spp));
      continue;
    }
    const auto start = std::chrono::steady_clock::now();
    LoadedGrid grid = loadFloatGrid(medium.vdbPath(frame), medium.densityGrid);
    BakedVolume bake = bakeVolume(grid, bakeOptions);
    GpuVolumeResources volume(ctx, bake, medium.densityScale);
    tracer.setVolume(volume);
    tracer.beginFrame(frame);
    for (int done = 0; done < rs.spp;) {
      const int n = std::min(a.batch, rs.spp - done);
      tracer.addSamples(n);
      done += n;
      if (bar) bar->advance(uint64_t(n));
    }
    Image image = tracer.readImage();
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const uint32_t truncated = volume.truncatedCount();
    if (truncated > 0) logWarn(strf("frame %d: %u tracking loops hit the step cap and were truncated", frame, truncated));
    image.meta["version"] = PLUME_VERSION;
    image.meta["mode"] = rs.mode;
    image.meta["spp"] = std::to_string(rs.spp);
    image.meta["seed"] = std::to_string(rs.seed);
    image.meta["frame"] = std::to_string(frame);
    image.meta["max_bounces"] = std::to_string(rs.maxBounces);
    image.meta["device"] = ctx.deviceName();
    image.meta["variant"] = tracer.features().name();
    image.meta["texels"] = texelFormatName(bake.format);
    image.meta["wall_time_s"] = strf("%.3f", seconds);
    image.meta["pass_times_last_batch"] = passTimesText(tracer.lastPassTimes());
    image.meta["tracking_truncated"] = std::to_string(truncated);
    image.meta["replaced_values"] = std::to_string(grid.replacedValues);
    image.meta["scene"] = a.scene;
    a.outputs.write(frame, image);
    if (a.quiet) continue;
    logInfo(strf("frame %d: %s  %.2fs (%s)", frame, a.outputs.exrPath(frame).c_str(), seconds,
                 passTimesText(tracer.lastPassTimes()).c_str()));
  }
  if (bar) bar->finish();
  return kExitOk;
}

}  // namespace

void addRenderCommand(CLI::App& app, Action& action) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand("render", "render frames with the Vulkan renderer (mean + variance EXR)");
  cmd->add_option("scene", args->scene, "scene JSON file")->required();
  cmd->add_option("-o,--output", args->outputs.pattern, "output EXR; {frame:04} is replaced by the frame")->required();
  cmd->add_flag("--png", args->outputs.png, "also write a tone-mapped PNG preview beside each EXR");
  cmd->add_flag("--resume", args->outputs.resume, "skip frames whose EXR is already complete");
  cmd->add_flag("-q,--quiet", args->quiet, "no progress bar or log lines");
  cmd->add_option("--width", args->width, "override camera.width")->check(CLI::Range(1, 16384));
  cmd->add_option("--height", args->height, "override camera.height")->check(CLI::Range(1, 16384));
  cmd->add_option("--batch", args->batch, "samples per pixel per dispatch")->check(CLI::Range(1, 4096));
  cmd->add_option("--device", args->device, "Vulkan device to use (substring of its name)");
  cmd->add_option("--texels", args->texels, "brick atlas storage: float16 (default) or float32")
      ->check(CLI::IsMember({"float16", "float32"}));
  addSettingOptions(*cmd, args->overrides);
  cmd->callback([&action, args] { action = [args] { return runRender(*args); }; });
}

}  // namespace plume
