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
#include "media/volume_frames.h"
#include "render/estimator.h"
#include "render/volume_source.h"
#include "scene/scene.h"

#include <algorithm>
#include <chrono>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace plume {
namespace {

struct RenderArgs : FrameJobArgs {
  int batch = 4;
  int preroll = 0;
  std::string device;
  std::string texels = "float16";
};

// The frames to warm up before `first`: up to K earlier frames, not before the animation's
// first frame (the scene file's render.frames[0], where the VDB sequence starts). Only estimators
// that carry state from frame to frame (temporal reuse) want them (DESIGN §8).
std::pair<int, int> prerollRange(const Scene& scene, int preroll, bool carriesHistory) {
  const int first = scene.render.frameFirst;
  if (preroll <= 0 || !carriesHistory) return {first, first - 1};
  return {std::max(scene.camera.baseFrame, first - preroll), first - 1};
}

// The frame loop of every estimator: --resume's skips, the pre-roll, one volume per frame (the
// previous one kept for estimators that carry history), progress, EXR header, writes.
int renderFrames(const RenderArgs& a, const Scene& scene, gpu::Context& ctx, Estimator& estimator,
                 VolumeSource& volumes, bool history, TexelFormat texels) {
  const RenderSettings& rs = scene.render;
  struct Job {
    int frame;
    bool write;  // false: pre-roll
    RenderKey key;
  };
  // Pre-roll frames (before render.frames' first) warm the history and are not written; dropped
  // unless the first frame is rendered (a frame skipped by --resume breaks the history anyway).
  const auto [warmFrom, warmTo] = prerollRange(scene, a.preroll, history);
  std::vector<Job> jobs;
  for (int frame = warmFrom; frame <= warmTo; ++frame) jobs.push_back({frame, false, {}});
  const size_t warm = jobs.size();
  for (int frame = rs.frameFirst; frame <= rs.frameLast; ++frame) {
    RenderKey key = estimator.renderKey(frame);
    key.add("texels", texelFormatName(texels));
    if (!a.outputs.skip(frame, key)) jobs.push_back({frame, true, std::move(key)});
  }
  if (jobs.size() == warm || jobs[warm].frame != rs.frameFirst) {
    jobs.erase(jobs.begin(), jobs.begin() + ptrdiff_t(warm));
  }
  FrameProgress progress(int(jobs.size()), rs.spp, !a.quiet);
  for (size_t j = 0; j < jobs.size(); ++j) {
    const int frame = jobs[j].frame;
    if (j > 0 ? jobs[j - 1].frame != frame - 1 : frame > rs.frameFirst) {  // after frames --resume skipped
      estimator.forgetHistory();
      if (history) logInfo(strf("frame %d: starts without history (frame %d was skipped)", frame, frame - 1));
    }
    const auto start = std::chrono::steady_clock::now();
    progress.beginFrame(frame);
    const GpuVolumeResources& volume = volumes.load(frame);
    estimator.setVolumes(volume, volumes.previous());
    estimator.renderFrame(frame, rs.spp, [&](int n) { progress.samplesDone(n); });
    const uint32_t truncated = volume.truncatedCount();
    if (truncated > 0) {
      logWarn(strf("frame %d: %u tracking loops hit the step cap and were truncated", frame, truncated));
    }
    const uint32_t loopCut = volume.loopLimitCount();
    if (loopCut > 0) {
      logWarn(strf("frame %d: the Vulkan driver cut the loops of %u shader invocations (llvmpipe ends every loop "
                   "once an invocation has run 65535 iterations): this image is biased; render with fewer "
                   "bounces or on another device",
                   frame, loopCut));
    }
    if (!jobs[j].write) {
      progress.frameWarmed(frame, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
      continue;
    }
    Image image = estimator.readImage();
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    setCommonMeta(image, {.mode = rs.mode, .spp = rs.spp, .seed = rs.seed, .frame = frame,
                          .maxBounces = rs.maxBounces, .device = ctx.deviceName()});
    setFrameJobMeta(image, a, jobs[j].key, volumes.replacedValues());
    image.meta["texels"] = texelFormatName(texels);
    image.meta["wall_time_s"] = strf("%.3f", seconds);
    image.meta["tracking_truncated"] = std::to_string(truncated);
    image.meta["driver_loop_limit_hits"] = std::to_string(loopCut);
    estimator.describe(image.meta);
    a.outputs.write(frame, image);
    progress.frameDone(frame, a.outputs.exrPath(frame), seconds, estimator.detail());
  }
  progress.finish();
  return kExitOk;
}

int runRender(const RenderArgs& a) {
  Scene scene = loadJobScene(a);
  const RenderSettings& rs = scene.render;
  const EstimatorKind kind = estimatorKind(rs);
  const EstimatorTraits& traits = estimatorTraits(kind);
  if (a.preroll > 0 && !traits.carriesHistory) {
    logInfo(strf("--preroll %d: no effect with mode %s (its frames are independent)", a.preroll, rs.mode.c_str()));
  }
  if (traits.check) traits.check(scene);
  a.outputs.check(rs);
  checkVolumeFrames(scene, prerollRange(scene, a.preroll, traits.carriesHistory).first, rs.frameLast);  // before the device starts
  VolumeSourceOptions volumeOptions;
  volumeOptions.bake.format = a.texels == "float32" ? TexelFormat::Float32 : TexelFormat::Float16;
  volumeOptions.bake.meanField = traits.needsMeanField;
  volumeOptions.keepPrevious = traits.carriesHistory;
  gpu::Context ctx({a.device, false, !a.quiet});
  gpu::ShaderCompiler compiler({}, gpu::ShaderCompiler::defaultCacheDir());
  std::unique_ptr<Estimator> estimator = makeEstimator(kind, ctx, compiler, scene, {.batch = a.batch});
  VolumeSource volumes(ctx, scene.medium(), volumeOptions);
  return renderFrames(a, scene, ctx, *estimator, volumes, traits.carriesHistory, volumeOptions.bake.format);
}

}  // namespace

void addRenderCommand(CLI::App& app, Action& action) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand("render", "render frames with the Vulkan renderer (mean + variance EXR)");
  addFrameJobOptions(*cmd, *args);
  cmd->add_option("--batch", args->batch, "path tracer: samples per pixel between progress updates (each dispatch renders one)")->check(CLI::Range(1, 4096));
  cmd->add_option("--preroll", args->preroll,
                  "warm temporal reuse on up to K frames before the first one (not written; for chunks that start "
                  "mid-sequence). No effect with --mode pt, whose frames are independent")
      ->check(CLI::Range(0, 1000));
  cmd->add_option("--device", args->device, "Vulkan device to use (substring of its name)");
  cmd->add_option("--texels", args->texels, "brick atlas storage: float16 (default) or float32")
      ->check(CLI::IsMember({"float16", "float32"}));
  cmd->callback([&action, args] { action = [args] { return runRender(*args); }; });
}

}  // namespace plume
