#include "viewer/view_renderer.h"

#include "core/error.h"
#include "media/vdb_loader.h"
#include "render/restir.h"

namespace plume::viewer {
namespace {

// The delta-tracking path tracer (DESIGN §4.1): frames are independent, so `continuous` is moot.
class PathTracerView final : public ViewRenderer {
 public:
  PathTracerView(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const Scene& scene)
      : tracer_(ctx, compiler, scene) {}
  std::string name() const override { return "path tracer [" + tracer_.features().name() + "]"; }
  void setVolume(const GpuVolumeResources& volume) override { tracer_.setVolume(volume); }
  void beginFrame(int frame, bool) override { tracer_.beginFrame(frame); }
  void addSamples(int spp) override { tracer_.addSamples(spp); }
  int samplesSoFar() const override { return tracer_.samplesSoFar(); }
  Image readImage() const override { return tracer_.readImage(); }
  const gpu::Buffer& accumulation() const override { return tracer_.accumulation(); }
  PassTimes lastPassTimes() const override { return tracer_.lastPassTimes(); }

 private:
  PathTracer tracer_;
};

// Volumetric ReSTIR (DESIGN §4.2). Temporal reuse follows the camera while the animation frame
// stays; a new animation frame (or an edit that breaks continuity) starts a fresh history, as
// the viewer keeps only the current frame's volume on the device. Progressive accumulation
// averages successive ReSTIR frames of a still view on the device (they are correlated through
// reuse; the average converges all the same).
class RestirView final : public ViewRenderer {
 public:
  RestirView(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const Scene& scene)
      : restir_(ctx, compiler, scene, restirOptionsOf(scene.render)) {}
  std::string name() const override { return "ReSTIR [" + restir_.options().name() + "]"; }
  void setVolume(const GpuVolumeResources& volume) override { restir_.setVolumes(volume, volume); }
  void beginFrame(int frame, bool continuous) override {
    if (!continuous || frame != frame_) restir_.resetHistory();
    frame_ = frame;
    samples_ = 0;
  }
  void addSamples(int spp) override {
    // Random streams are keyed frame * 1024 + iteration: every 1024 iterations the viewer moves
    // to the next seed sequence (a fresh history) instead of reusing numbers or stopping.
    for (int i = 0; i < spp; ++i, ++samples_, ++iteration_) {
      restir_.render(frame_, iteration_ / Restir::kMaxIterations, iteration_ % Restir::kMaxIterations, samples_ > 0);
    }
  }
  int samplesSoFar() const override { return samples_; }
  Image readImage() const override { return restir_.readImage(); }
  const gpu::Buffer& accumulation() const override { return restir_.accumulation(); }
  PassTimes lastPassTimes() const override { return restir_.lastPassTimes(); }

 private:
  Restir restir_;
  int frame_ = 0;
  uint32_t iteration_ = 0;
  int samples_ = 0;
};

}  // namespace

const std::vector<ModeInfo>& viewModes() {
  static const std::vector<ModeInfo> modes = {
      {"pt", true, ""},
      {"restir", true, ""},
      {"restir-biased", true, ""},
  };
  return modes;
}

std::unique_ptr<ViewRenderer> makeViewRenderer(gpu::Context& ctx, gpu::ShaderCompiler& compiler,
                                               const Scene& scene) {
  const std::string& mode = scene.render.mode;
  if (mode == "pt") return std::make_unique<PathTracerView>(ctx, compiler, scene);
  if (mode == "restir" || mode == "restir-biased") return std::make_unique<RestirView>(ctx, compiler, scene);
  throw InputError(scene.path + ": render.mode: \"" + mode + "\" is not available in the viewer yet; use \"pt\"");
}

const BakedVolume& VolumeCache::bake(int frame) {
  const std::string path = medium_.vdbPath(frame);  // a still volume is baked once
  auto it = bakes_.find(path);
  if (it == bakes_.end()) {
    LoadedGrid grid = loadFloatGrid(path, medium_.densityGrid);
    it = bakes_.emplace(path, bakeVolume(grid, options_)).first;
  }
  return it->second;
}

const GpuVolumeResources& VolumeCache::volume(int frame, float densityScale) {
  if (!current_ || medium_.vdbPath(frame) != currentPath_) {
    const BakedVolume& b = bake(frame);
    current_.reset();  // free the old device copy first
    current_ = std::make_unique<GpuVolumeResources>(ctx_, b, densityScale);
    currentPath_ = medium_.vdbPath(frame);
  } else {
    current_->setDensityScale(densityScale);  // the density slider: no re-upload of the grid
  }
  return *current_;
}

}  // namespace plume::viewer
