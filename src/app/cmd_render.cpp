// plume render SCENE -o OUT.exr: the Vulkan renderer over frame sequences (DESIGN §4, §8).
#include "app/commands.h"
#include "app/frame_output.h"
#include "app/settings_cli.h"
#include "core/error.h"
#include "core/log.h"
#include "gpu/context.h"
#include "gpu/shader_compiler.h"
#include "media/bake.h"
#include "media/vdb_loader.h"
#include "media/volume_frames.h"
#include "render/gpu_volume.h"
#include "render/path_tracer.h"
#include "render/restir.h"
#include "scene/scene.h"

#include <chrono>
#include <functional>
#include <map>
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

std::string passTimesText(const PassTimes& times) {
  std::string s;
  for (const auto& [name, ms] : times) s += strf("%s%s %.2f ms", s.empty() ? "" : ", ", name.c_str(), ms);
  return s;
}

// Estimators that carry state from frame to frame (temporal reuse) want a few earlier frames
// rendered, not written, when a chunk starts mid-sequence (DESIGN §8). The path tracer's frames
// are independent: nothing to warm.
bool carriesHistory(const std::string& mode) { return mode == "restir" || mode == "restir-biased"; }

// The frames to warm up before `first`: up to K earlier frames, not before the animation's
// first frame (the scene file's render.frames[0], where the VDB sequence starts).
std::pair<int, int> prerollRange(const Scene& scene, int preroll) {
  const int first = scene.render.frameFirst;
  if (preroll <= 0 || !carriesHistory(scene.render.mode)) return {first, first - 1};
  return {std::max(scene.camera.baseFrame, first - preroll), first - 1};
}

// One estimator behind the frame loop (renderFrames): it renders a frame's samples over the
// frame's volume, names the settings its pixels depend on, and describes itself and its last
// frame for the EXR header and the log.
class FrameEstimator {
 public:
  using SamplesDone = std::function<void(int)>;
  virtual ~FrameEstimator() = default;
  // Renders `frame` over `volume`; `previous` is the volume of the frame rendered just before in
  // this run (null at the start and after a gap), for estimators that carry history.
  // samplesDone(n) after every n samples per pixel (ReSTIR: iterations).
  virtual void render(int frame, const GpuVolumeResources& volume, const GpuVolumeResources* previous,
                      const SamplesDone& samplesDone) = 0;
  virtual Image readImage() const = 0;
  // The next frame starts without history (the frame before it was not rendered in this run).
  virtual void forgetHistory() {}
  // The frame's render key (app/frame_output.h) as far as the estimator knows it.
  virtual RenderKey key(int frame) const = 0;
  // Header entries: variant, the estimator's settings, the last frame's timings and counters.
  virtual void describe(std::map<std::string, std::string>& meta) const = 0;
  // The last frame's timings and counters for its log line.
  virtual std::string detail() const = 0;
};

// The path tracer: render.spp samples per pixel in dispatches of --batch (DESIGN §4.1).
class PathTracerFrames final : public FrameEstimator {
 public:
  PathTracerFrames(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const Scene& scene, int batch)
      : scene_(scene), tracer_(ctx, compiler, scene), batch_(batch) {}

  void render(int frame, const GpuVolumeResources& volume, const GpuVolumeResources*,
              const SamplesDone& samplesDone) override {
    tracer_.setVolume(volume);
    tracer_.beginFrame(frame);
    for (int done = 0; done < scene_.render.spp;) {
      const int n = std::min(batch_, scene_.render.spp - done);
      tracer_.addSamples(n);
      done += n;
      samplesDone(n);
    }
  }
  Image readImage() const override { return tracer_.readImage(); }
  RenderKey key(int frame) const override {
    RenderKey key = sceneRenderKey(scene_, frame, [](const std::string& k) { return k.rfind("restir_", 0) != 0; });
    key.add("batch", std::to_string(batch_));  // the running mean is merged per dispatch: the last bits differ
    return key;
  }
  void describe(std::map<std::string, std::string>& meta) const override {
    meta["variant"] = tracer_.variantName();
    meta["batch"] = std::to_string(batch_);
    meta["pass_times_last_batch"] = passTimesText(tracer_.lastPassTimes());
  }
  std::string detail() const override { return passTimesText(tracer_.lastPassTimes()); }

 private:
  const Scene& scene_;
  PathTracer tracer_;
  int batch_;
};

// ReSTIR: render.spp iterations per frame (one sample per pixel each), history kept across
// iterations and frames; mean and variance of the iterations after the first eighth (correlated
// by reuse, so the variance is a rough guide only).
class RestirFrames final : public FrameEstimator {
 public:
  RestirFrames(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const Scene& scene)
      : scene_(scene), restir_(ctx, compiler, scene, restirOptionsOf(scene.render)) {}

  void render(int frame, const GpuVolumeResources& volume, const GpuVolumeResources* previous,
              const SamplesDone& samplesDone) override {
    if (!hasHistory_ || restir_.options().historyCap == 0) historyFrom_ = frame;
    restir_.setVolumes(volume, previous ? *previous : volume);
    // The first eighth of the iterations settle the reservoirs on the frame's grid and are not
    // averaged (every iteration is unbiased, so any subset fixed in advance is). Frames 10-12 of
    // the bundled smoke, 12 iterations, history cap 8, frame 12's relMSE for seeds 1 / 7: none
    // settling 0.00063 / 0.00061, one 0.00059 / 0.00056, two 0.00059 / 0.00056, three 0.00062 /
    // 0.00058 (notes/restir.md).
    const int spp = scene_.render.spp, settle = spp / 8;
    averaged_ = spp - settle;
    restir_.takeDroppedCount();  // counted from here: this frame's iterations
    for (int i = 0; i < spp; ++i) {
      if (i == 1) restir_.setVolumes(volume, volume);
      restir_.render(frame, 0, uint32_t(i), i > settle);
      samplesDone(1);
    }
    dropped_ = restir_.takeDroppedCount();
    hasHistory_ = true;
  }
  Image readImage() const override { return restir_.readImage(); }
  void forgetHistory() override {
    restir_.resetHistory();
    hasHistory_ = false;
  }
  RenderKey key(int frame) const override {
    return sceneRenderKey(scene_, frame, [](const std::string&) { return true; });
  }
  void describe(std::map<std::string, std::string>& meta) const override {
    meta["variant"] = restir_.features().name();
    meta["restir"] = restir_.options().name();
    meta["restir_iterations_averaged"] = std::to_string(averaged_);
    // The first frame of the unbroken run of frames whose history this frame's reservoirs carry
    // (the frame itself without temporal reuse): its pixels depend on where that run started.
    meta["restir_history_from"] = std::to_string(historyFrom_);
    meta["pass_times_last_iteration"] = passTimesText(restir_.lastPassTimes());
    meta["dropped_non_finite_reservoirs"] = std::to_string(dropped_);
  }
  std::string detail() const override {
    return strf("%s; dropped %u", passTimesText(restir_.lastPassTimes()).c_str(), dropped_);
  }

 private:
  const Scene& scene_;
  Restir restir_;
  bool hasHistory_ = false;
  int historyFrom_ = 0;
  int averaged_ = 0;      // iterations in the frame's mean (the last ones, after those that settle)
  uint32_t dropped_ = 0;  // unpacks whose non-finite weights were dropped, summed over the frame's iterations
};

// The frame loop of every estimator: --resume's skips, the pre-roll, one volume per frame (the
// previous one kept for estimators that carry history), progress, EXR header, writes.
int renderFrames(const RenderArgs& a, const Scene& scene, gpu::Context& ctx, FrameEstimator& estimator,
                 const BakeOptions& bakeOptions) {
  const RenderSettings& rs = scene.render;
  const Medium& medium = scene.medium();
  const bool history = carriesHistory(rs.mode);
  struct Job {
    int frame;
    bool write;  // false: pre-roll
    RenderKey key;
  };
  // Pre-roll frames (before render.frames' first) warm the history and are not written; dropped
  // unless the first frame is rendered (a frame skipped by --resume breaks the history anyway).
  const auto [warmFrom, warmTo] = prerollRange(scene, a.preroll);
  std::vector<Job> jobs;
  for (int frame = warmFrom; frame <= warmTo; ++frame) jobs.push_back({frame, false, {}});
  const size_t warm = jobs.size();
  for (int frame = rs.frameFirst; frame <= rs.frameLast; ++frame) {
    RenderKey key = estimator.key(frame);
    key.add("texels", texelFormatName(bakeOptions.format));
    if (!a.outputs.skip(frame, key)) jobs.push_back({frame, true, std::move(key)});
  }
  if (jobs.size() == warm || jobs[warm].frame != rs.frameFirst) {
    jobs.erase(jobs.begin(), jobs.begin() + ptrdiff_t(warm));
  }
  FrameProgress progress(int(jobs.size()), rs.spp, !a.quiet);
  std::unique_ptr<GpuVolumeResources> previous;
  for (size_t j = 0; j < jobs.size(); ++j) {
    const int frame = jobs[j].frame;
    if (j > 0 ? jobs[j - 1].frame != frame - 1 : frame > rs.frameFirst) {  // after frames --resume skipped
      estimator.forgetHistory();
      previous.reset();
      if (history) logInfo(strf("frame %d: starts without history (frame %d was skipped)", frame, frame - 1));
    }
    const auto start = std::chrono::steady_clock::now();
    progress.beginFrame(frame);
    LoadedGrid grid = loadFloatGrid(medium.vdbPath(frame), medium.densityGrid);
    auto volume = std::make_unique<GpuVolumeResources>(ctx, bakeVolume(grid, bakeOptions), medium.densityScale);
    estimator.render(frame, *volume, previous.get(), [&](int n) { progress.samplesDone(n); });
    const uint32_t truncated = volume->truncatedCount();
    if (truncated > 0) {
      logWarn(strf("frame %d: %u tracking loops hit the step cap and were truncated", frame, truncated));
    }
    previous = history ? std::move(volume) : nullptr;
    if (!jobs[j].write) {
      progress.frameWarmed(frame, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
      continue;
    }
    Image image = estimator.readImage();
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    image.meta["version"] = PLUME_VERSION;
    image.meta["mode"] = rs.mode;
    image.meta["spp"] = std::to_string(rs.spp);
    image.meta["seed"] = std::to_string(rs.seed);
    image.meta["frame"] = std::to_string(frame);
    image.meta["max_bounces"] = std::to_string(rs.maxBounces);
    image.meta["device"] = ctx.deviceName();
    image.meta["texels"] = texelFormatName(bakeOptions.format);
    image.meta["wall_time_s"] = strf("%.3f", seconds);
    image.meta["tracking_truncated"] = std::to_string(truncated);
    image.meta["replaced_values"] = std::to_string(grid.replacedValues);
    image.meta["scene"] = a.scene;
    image.meta["render_key"] = jobs[j].key.text();
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
  if (a.preroll > 0 && !carriesHistory(rs.mode)) {
    logInfo(strf("--preroll %d: no effect with mode %s (its frames are independent)", a.preroll, rs.mode.c_str()));
  }
  if (rs.mode != "pt" && rs.spp > int(Restir::kMaxIterations)) {
    throw InputError(scene.path + strf(": render.spp: at most %u ReSTIR iterations per frame (got %d)",
                                       Restir::kMaxIterations, rs.spp));
  }
  a.outputs.check(rs);
  checkVolumeFrames(scene, prerollRange(scene, a.preroll).first, rs.frameLast);  // before the device starts
  BakeOptions bakeOptions;
  bakeOptions.format = a.texels == "float32" ? TexelFormat::Float32 : TexelFormat::Float16;
  bakeOptions.meanField = rs.mode != "pt";  // only ReSTIR reads it
  gpu::Context ctx({a.device, false, !a.quiet});
  gpu::ShaderCompiler compiler({}, gpu::ShaderCompiler::defaultCacheDir());
  // Mode dispatch: the one place that picks the estimator.
  std::unique_ptr<FrameEstimator> estimator;
  if (rs.mode == "pt") {
    estimator = std::make_unique<PathTracerFrames>(ctx, compiler, scene, a.batch);
  } else {
    estimator = std::make_unique<RestirFrames>(ctx, compiler, scene);  // restir, restir-biased (render/restir.h)
  }
  return renderFrames(a, scene, ctx, *estimator, bakeOptions);
}

}  // namespace

void addRenderCommand(CLI::App& app, Action& action) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand("render", "render frames with the Vulkan renderer (mean + variance EXR)");
  addFrameJobOptions(*cmd, *args);
  cmd->add_option("--batch", args->batch, "samples per pixel per dispatch")->check(CLI::Range(1, 4096));
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
