// What the viewer drives, whatever the estimator: begin a frame (camera, animation frame and
// parameters taken from the Scene the renderer was built with), add samples progressively, read
// the image back. `makeViewRenderer` is the one place where the viewer dispatches on
// render.mode (pt, restir, restir-biased).
#pragma once

#include "gpu/context.h"
#include "gpu/shader_compiler.h"
#include "io/image.h"
#include "media/bake.h"
#include "render/gpu_volume.h"
#include "render/path_tracer.h"
#include "scene/scene.h"

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace plume::viewer {

class ViewRenderer {
 public:
  virtual ~ViewRenderer() = default;
  virtual std::string name() const = 0;
  virtual void setVolume(const GpuVolumeResources& volume) = 0;
  // `continuous`: the same animation sequence goes on (camera or frame changed): estimators with
  // temporal reuse keep their history; false after a parameter edit that invalidates it.
  virtual void beginFrame(int frame, bool continuous) = 0;
  virtual void addSamples(int spp) = 0;
  virtual int samplesSoFar() const = 0;
  virtual Image readImage() const = 0;
  // The accumulation on the device (render/gpu_scene.h readAccumulation's layout), which the
  // display pass tone-maps in place: no read-back per frame.
  virtual const gpu::Buffer& accumulation() const = 0;
  virtual PassTimes lastPassTimes() const = 0;
};

struct ModeInfo {
  std::string mode;    // render.mode value
  bool available;      // a renderer for it is built in
  std::string note;    // shown in the UI when not available
};
const std::vector<ModeInfo>& viewModes();

// The renderer for scene.render.mode. `scene` must outlive it (it reads camera, media and
// settings at every beginFrame). Throws InputError for a mode that is not available.
std::unique_ptr<ViewRenderer> makeViewRenderer(gpu::Context& ctx, gpu::ShaderCompiler& compiler,
                                               const Scene& scene);

// Bakes of the animation's frames, kept once made (bundled sequences are small; the viewer
// steps back and forth), and the device copy of the current one.
class VolumeCache {
 public:
  VolumeCache(gpu::Context& ctx, const Medium& medium, BakeOptions options) : ctx_(ctx), medium_(medium), options_(options) {}
  // The device volume for `frame` with `densityScale`: rebuilt when the frame's file changes, its
  // density scale set in place otherwise.
  const GpuVolumeResources& volume(int frame, float densityScale);
  const BakedVolume& bake(int frame);

 private:
  gpu::Context& ctx_;
  const Medium& medium_;
  BakeOptions options_;
  std::map<std::string, BakedVolume> bakes_;  // by file
  std::unique_ptr<GpuVolumeResources> current_;
  std::string currentPath_;
};

}  // namespace plume::viewer
