// The GPU delta-tracking path tracer (DESIGN §4.1) on top of the baked volume, organised as a
// wavefront (shaders/pt/wavefront.glsl): generations of path slots (a sample of a pixel each) go
// through an extension kernel (to the next real collision) and a shading kernel (next-event
// estimation, roulette, phase sampling) over queues until every path has ended, then are merged
// into the progressive accumulation of the mean and M2 per pixel, read back as mean + variance of
// the mean. The kernels are compiled for the scene's feature set.
#pragma once

#include "gpu/pipeline.h"
#include "gpu/shader_compiler.h"
#include "io/image.h"
#include "render/features.h"
#include "render/gpu_envmap.h"
#include "render/gpu_surfaces.h"
#include "render/gpu_volume.h"
#include "render/pixel_order.h"
#include "scene/scene.h"

#include <memory>
#include <string>

namespace plume {

class PathTracer {
 public:
  // kernelCounters: FeatureSet::kernelCounters (the kernel benchmark only). bufferLimit: the
  // largest storage buffer to allocate (0: the device's maxStorageBufferRange; tests set less to
  // split a small image's accumulation into bands).
  PathTracer(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const Scene& scene, bool kernelCounters = false,
             VkDeviceSize bufferLimit = 0);

  const FeatureSet& features() const { return features_; }
  bool hasSurfaces() const { return surfaces_ != nullptr; }  // a BVH was built (the scene has surfaces)
  // Binds a volume; call again when the volume changes (animation). Large brick grids use the
  // empty-space-skipping variant of the tracking code (compiled on first use).
  void setVolume(const GpuVolumeResources& volume);
  // The shader variant in use, e.g. "sun+env+multi" or "sun+env+multi+skip".
  std::string variantName() const;
  // Clears the accumulation and sets the camera and seeds for `frame`.
  void beginFrame(int frame);
  // Traces `spp` more samples per pixel (waits for them).
  void addSamples(int spp);
  // Path slots per generation (samples of several pixels traced together): whole samples of the
  // image up to about kGenerationPaths; a larger image in bands of kGenerationPaths pixels with up
  // to kMaxSlots / kGenerationPaths samples each (path_tracer.cpp). One sample per generation made each
  // sample pay ~max_bounces rounds of dispatches and a resolve pass: on lavapipe 2^18 paths took
  // the bundled smoke's 128² path tracer from ~7.7 to ~4.3 ms per sample and 256² by ~20%
  // (notes/bench/kernels.md "Session 20"); 2^20 was no faster than 2^18.
  static constexpr uint32_t kMaxSlots = 1u << 20;
  static constexpr uint32_t kGenerationPaths = 1u << 18;
  int samplesSoFar() const { return samples_; }
  // Samples of every pixel of its band that one generation holds.
  uint32_t samplesPerGeneration() const;
  // Pixels per generation: the whole image, or bands of kGenerationPaths pixels.
  uint32_t generationPixels() const { return bandPixels_; }
  Image readImage() const;  // mean + variance of the mean
  // The accumulation on the device (render/gpu_scene.h readAccumulation's layout), for a display
  // pass that reads it in place. Throws InputError where the image needs more than one band.
  const gpu::Buffer& accumulation() const;
  // Buffers the accumulation is split into (a whole number of generation bands each): one unless
  // the image's accumulation exceeds the device's largest storage buffer.
  size_t accumulationBands() const { return accums_.size(); }
  const PassTimes& lastPassTimes() const { return passTimes_; }

 private:
  gpu::Context& ctx_;
  const Scene& scene_;
  FeatureSet features_;
  std::unique_ptr<GpuEnvironmentMap> envMap_;
  std::unique_ptr<GpuSurfaces> surfaces_;  // only for a scene with surfaces
  struct Tracking {  // the kernels that walk the volume, per variant
    std::unique_ptr<gpu::ComputePass> camera, extend, shade;
  };
  Tracking& tracking(bool skipEmpty);
  gpu::BindingTypes volumeTypes() const;
  std::unique_ptr<gpu::ComputePass> makePass(const std::string& file, const gpu::ShaderDefines& defines,
                                             const std::string& name, bool volumeTable);
  // Traces samples [sampleBase, sampleBase + samples) of pixels [pixelBegin, pixelBegin + pixels)
  // to their ends and merges them into the accumulation.
  void traceGeneration(uint32_t pixelBegin, uint32_t pixels, uint32_t sampleBase, uint32_t samples);
  void addTimes();  // the timer's scopes into passTimes_, summed by pass

  gpu::ShaderCompiler& compiler_;
  Tracking tracking_[2];  // [skip empty space]
  Tracking* active_ = nullptr;
  std::unique_ptr<gpu::ComputePass> queue_;
  std::vector<std::unique_ptr<gpu::ComputePass>> resolves_;  // one per accumulation band
  // The pixels whose every camera ray misses the scene (the end of the pixel list), finished
  // without slots; only where the scene has no surfaces and the accumulation is one buffer.
  std::unique_ptr<gpu::ComputePass> background_;
  // The pixel list (render/pixel_order.h): the pixels whose rays may meet the volume first, in
  // tile order, then the others; without a background pass no list (row order, all inside).
  // Rebuilt when the camera or the volume changes.
  void orderPixels();
  bool ordered_ = false;
  VolumeFootprint footprint_;
  uint64_t volumeSerial_ = 0, orderSerial_ = 0;
  shared::GpuCamera orderCam_{};
  PixelOrder order_;
  gpu::TexelBuffer pixelList_;
  bool skipEmpty_ = false;
  gpu::GpuTimer timer_;
  gpu::Buffer frameBuffer_;
  std::vector<gpu::Buffer> accums_;  // the accumulation in parts of accumPixels_ pixels
  uint32_t accumPixels_ = 0;
  uint32_t bandPixels_ = 0;           // pixels per generation
  gpu::TexelBuffer lightBuffer_;
  gpu::TexelBuffer paths_;             // the wavefront's path slots (a storage texel buffer)
  gpu::Buffer queues_, wave_;          // its queues and PtWave
  uint32_t slots_ = 0;                 // path slots allocated
  shared::GpuFrame frame_{};
  int samples_ = 0;
  PassTimes passTimes_;
};

}  // namespace plume
