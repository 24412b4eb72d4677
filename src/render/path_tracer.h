// The GPU delta-tracking path tracer (DESIGN §4.1) on top of the baked volume: one compute pass
// (shaders/passes/pt.comp) compiled for the scene's feature set, progressive accumulation of the
// mean and M2 per pixel, read back as mean + variance of the mean.
#pragma once

#include "gpu/pipeline.h"
#include "gpu/shader_compiler.h"
#include "io/image.h"
#include "render/features.h"
#include "render/gpu_envmap.h"
#include "render/gpu_volume.h"
#include "scene/scene.h"

#include <memory>
#include <string>

namespace plume {

class PathTracer {
 public:
  // kernelCounters: FeatureSet::kernelCounters (the kernel benchmark only).
  PathTracer(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const Scene& scene, bool kernelCounters = false);

  const FeatureSet& features() const { return features_; }
  // Binds a volume; call again when the volume changes (animation). Large brick grids use the
  // empty-space-skipping variant of the tracking code (compiled on first use).
  void setVolume(const GpuVolumeResources& volume);
  // The shader variant in use, e.g. "sun+env+multi" or "sun+env+multi+skip".
  std::string variantName() const;
  // Clears the accumulation and sets the camera and seeds for `frame`.
  void beginFrame(int frame);
  // Traces `spp` more samples per pixel (one dispatch, waits for it).
  void addSamples(int spp);
  int samplesSoFar() const { return samples_; }
  Image readImage() const;  // mean + variance of the mean
  // The accumulation on the device (render/gpu_scene.h readAccumulation's layout), for a display
  // pass that reads it in place.
  const gpu::Buffer& accumulation() const { return accum_; }
  const PassTimes& lastPassTimes() const { return passTimes_; }

 private:
  gpu::Context& ctx_;
  const Scene& scene_;
  FeatureSet features_;
  std::unique_ptr<GpuEnvironmentMap> envMap_;
  gpu::ComputePass& makePass(bool skipEmpty);

  gpu::ShaderCompiler& compiler_;
  std::unique_ptr<gpu::ComputePass> passes_[2];  // [skip empty space]
  gpu::ComputePass* pass_ = nullptr;
  bool skipEmpty_ = false;
  gpu::GpuTimer timer_;
  gpu::Buffer frameBuffer_, lightBuffer_, accum_;
  shared::GpuFrame frame_{};
  int samples_ = 0;
  PassTimes passTimes_;
};

}  // namespace plume
