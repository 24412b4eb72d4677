// Volumetric ReSTIR (DESIGN §4.2, render/restir.h) behind the Estimator interface: "restir"
// (the MIS of render.restir_mis) and "restir-biased" (1/M resampling, RS_MIS_BIASED). One sample
// per pixel per iteration; the history is kept across iterations and frames.
#include "core/error.h"
#include "core/log.h"
#include "render/estimator.h"
#include "render/restir.h"

namespace plume {
namespace {

// Every setting, but the shift only with surfaces: without them it changes nothing (the same
// images), so frames of such scenes rendered before the setting existed stay valid for --resume.
bool usesSetting(const Scene& scene, const std::string& key) { return !scene.surfaces.empty() || key != "restir_shift"; }

class RestirEstimator final : public Estimator {
 public:
  RestirEstimator(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const Scene& scene, const RestirOptions& options,
                  bool kernelCounters)
      : scene_(scene), restir_(ctx, compiler, scene, options, kernelCounters) {}

  std::string name() const override { return "ReSTIR [" + restir_.options().name() + "]"; }
  void setVolumes(const GpuVolumeResources& current, const GpuVolumeResources* previous) override {
    current_ = &current;
    restir_.setVolumes(current, previous ? *previous : current);
  }
  void forgetHistory() override {
    restir_.resetHistory();
    hasHistory_ = false;
  }

  // Mean and variance of the iterations after the first eighth (correlated by reuse, so the
  // variance is a rough guide only).
  void renderFrame(int frame, int spp, const SamplesDone& samplesDone) override {
    if (!hasHistory_ || restir_.options().historyCap == 0) historyFrom_ = frame;
    // The first eighth of the iterations settle the reservoirs on the frame's grid and are not
    // averaged (every iteration is unbiased, so any subset fixed in advance is). Frames 10-12 of
    // the bundled smoke, 12 iterations, history cap 8, frame 12's relMSE for seeds 1 / 7: none
    // settling 0.00063 / 0.00061, one 0.00059 / 0.00056, two 0.00059 / 0.00056, three 0.00062 /
    // 0.00058 (notes/restir.md).
    const int settle = spp / 8;
    averaged_ = spp - settle;
    restir_.takeDroppedCount();  // counted from here: this frame's iterations
    for (int i = 0; i < spp; ++i) {
      if (i == 1) restir_.setVolumes(*current_, *current_);  // the history is this frame's from here on
      restir_.render(frame, 0, uint32_t(i), i > settle);
      if (samplesDone) samplesDone(1);
    }
    dropped_ = restir_.takeDroppedCount();
    hasHistory_ = true;
    samples_ = averaged_;
  }
  void beginFrame(int frame) override {
    frame_ = frame;
    samples_ = 0;
  }
  // Progressive accumulation averages successive ReSTIR frames of a still view on the device
  // (correlated through reuse; the average converges all the same). Random streams are keyed
  // frame * 1024 + iteration: every 1024 iterations the count moves to the next seed sequence (a
  // fresh history) instead of reusing numbers or stopping.
  void addSamples(int n) override {
    for (int i = 0; i < n; ++i, ++samples_, ++iteration_) {
      restir_.render(frame_, iteration_ / Restir::kMaxIterations, iteration_ % Restir::kMaxIterations, samples_ > 0);
    }
    hasHistory_ = true;
  }
  int samplesSoFar() const override { return samples_; }

  Image readImage() const override { return restir_.readImage(); }
  const gpu::Buffer& accumulation() const override { return restir_.accumulation(); }
  const PassTimes& lastPassTimes() const override { return restir_.lastPassTimes(); }

  RenderKey renderKey(int frame) const override {
    return sceneRenderKey(scene_, frame, [this](const std::string& k) { return usesSetting(scene_, k); });
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
  const GpuVolumeResources* current_ = nullptr;
  bool hasHistory_ = false;
  int historyFrom_ = 0;
  int averaged_ = 0;      // iterations in the frame's mean (the last ones, after those that settle)
  uint32_t dropped_ = 0;  // unpacks whose non-finite weights were dropped, summed over the frame's iterations
  int frame_ = 0;         // progressive: the frame begun
  int samples_ = 0;       // iterations in the accumulation
  uint32_t iteration_ = 0;  // progressive: iterations so far, across frames
};

RestirOptions optionsFor(const Scene& scene, bool biased) {
  RestirOptions o = restirOptionsOf(scene.render);
  if (biased) o.mis = shared::RS_MIS_BIASED;
  return o;
}

}  // namespace

EstimatorTraits restirTraits() {
  EstimatorTraits t;
  t.carriesHistory = true;
  t.needsMeanField = true;
  t.check = [](const Scene& scene) {
    if (scene.render.spp > int(Restir::kMaxIterations)) {
      throw InputError(scene.path + strf(": render.spp: at most %u ReSTIR iterations per frame (got %d)",
                                         Restir::kMaxIterations, scene.render.spp));
    }
  };
  t.usesSetting = usesSetting;
  return t;
}

std::unique_ptr<Estimator> makeRestirEstimator(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const Scene& scene,
                                               const EstimatorOptions& options) {
  return std::make_unique<RestirEstimator>(ctx, compiler, scene, optionsFor(scene, false), options.kernelCounters);
}

std::unique_ptr<Estimator> makeRestirBiasedEstimator(gpu::Context& ctx, gpu::ShaderCompiler& compiler,
                                                     const Scene& scene, const EstimatorOptions& options) {
  return std::make_unique<RestirEstimator>(ctx, compiler, scene, optionsFor(scene, true), options.kernelCounters);
}

}  // namespace plume
