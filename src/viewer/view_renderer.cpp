#include "viewer/view_renderer.h"

#include "core/error.h"
#include "media/vdb_loader.h"

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
  PassTimes lastPassTimes() const override { return tracer_.lastPassTimes(); }

 private:
  PathTracer tracer_;
};

}  // namespace

const std::vector<ModeInfo>& viewModes() {
  static const std::vector<ModeInfo> modes = {
      {"pt", true, ""},
      {"restir", false, "ReSTIR is being built (src/render/restir*); this switch enables itself when it lands"},
      {"restir-biased", false, "ReSTIR is being built (src/render/restir*); this switch enables itself when it lands"},
  };
  return modes;
}

std::unique_ptr<ViewRenderer> makeViewRenderer(gpu::Context& ctx, gpu::ShaderCompiler& compiler,
                                               const Scene& scene) {
  const std::string& mode = scene.render.mode;
  if (mode == "pt") return std::make_unique<PathTracerView>(ctx, compiler, scene);
  // ReSTIR hook: add `if (mode == "restir" || mode == "restir-biased") return
  // std::make_unique<RestirView>(...)` here, a ViewRenderer whose beginFrame(frame, true) keeps
  // the temporal history, and mark the modes available in viewModes().
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
  if (!current_ || medium_.vdbPath(frame) != currentPath_ || densityScale != currentScale_) {
    const BakedVolume& b = bake(frame);
    current_.reset();  // free the old device copy first
    current_ = std::make_unique<GpuVolumeResources>(ctx_, b, densityScale);
    currentPath_ = medium_.vdbPath(frame);
    currentScale_ = densityScale;
  }
  return *current_;
}

}  // namespace plume::viewer
