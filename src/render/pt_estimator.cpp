// The delta-tracking path tracer (DESIGN §4.1, render/path_tracer.h) behind the Estimator
// interface: its frames are independent, so it keeps no history.
#include "render/estimator.h"
#include "render/path_tracer.h"

#include <algorithm>

namespace plume {
namespace {

// Everything but ReSTIR's settings.
bool usesSetting(const Scene&, const std::string& key) { return key.rfind("restir_", 0) != 0; }

class PathTracerEstimator final : public Estimator {
 public:
  PathTracerEstimator(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const Scene& scene, int batch,
                      bool kernelCounters)
      : scene_(scene), tracer_(ctx, compiler, scene, kernelCounters), batch_(batch) {}

  std::string name() const override { return "path tracer [" + tracer_.features().name() + "]"; }
  void setVolumes(const GpuVolumeResources& current, const GpuVolumeResources*) override { tracer_.setVolume(current); }

  // `spp` samples per pixel, reported to samplesDone every `batch`.
  void renderFrame(int frame, int spp, const SamplesDone& samplesDone) override {
    tracer_.beginFrame(frame);
    for (int done = 0; done < spp;) {
      const int n = std::min(batch_, spp - done);
      tracer_.addSamples(n);
      done += n;
      if (samplesDone) samplesDone(n);
    }
  }
  void beginFrame(int frame) override { tracer_.beginFrame(frame); }
  void addSamples(int n) override { tracer_.addSamples(n); }
  int samplesSoFar() const override { return tracer_.samplesSoFar(); }

  Image readImage() const override { return tracer_.readImage(); }
  const gpu::Buffer& accumulation() const override { return tracer_.accumulation(); }
  const PassTimes& lastPassTimes() const override { return tracer_.lastPassTimes(); }

  RenderKey renderKey(int frame) const override {
    RenderKey key = sceneRenderKey(scene_, frame, [this](const std::string& k) { return usesSetting(scene_, k); });
    key.add("batch", std::to_string(batch_));  // frames from before session 7 depend on it (docs/farm.md)
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

}  // namespace

EstimatorTraits pathTracerTraits() {
  EstimatorTraits t;
  t.usesSetting = usesSetting;
  return t;
}

std::unique_ptr<Estimator> makePathTracerEstimator(gpu::Context& ctx, gpu::ShaderCompiler& compiler,
                                                   const Scene& scene, const EstimatorOptions& options) {
  return std::make_unique<PathTracerEstimator>(ctx, compiler, scene, options.batch, options.kernelCounters);
}

}  // namespace plume
