// One interface for the GPU estimators (DESIGN §4): what `plume render`, `plume view` and
// `plume bench` drive, whichever estimator it is. render.mode is parsed once (estimatorKind);
// the table in estimator.cpp is the only place that maps a kind to its implementation, so a new
// estimator is one file (a class implementing Estimator) and one line there.
#pragma once

#include "core/image.h"
#include "gpu/context.h"
#include "gpu/resources.h"
#include "gpu/shader_compiler.h"
#include "render/features.h"
#include "render/gpu_volume.h"
#include "scene/render_key.h"
#include "scene/scene.h"

#include <functional>
#include <map>
#include <memory>
#include <string>

namespace plume {

enum class EstimatorKind { PathTracer, Restir, RestirBiased };

// render.mode ("pt", "restir", "restir-biased"; the settings table has checked the text).
EstimatorKind estimatorKind(const RenderSettings& rs);

// What is known of an estimator before the device starts.
struct EstimatorTraits {
  // Frames depend on the frames before them (temporal reuse): a chunk may pre-roll, and a frame
  // --resume skipped breaks the history. The path tracer's frames are independent.
  bool carriesHistory = false;
  // Reads the bake's mean field (BakeOptions::meanField).
  bool needsMeanField = false;
  // Throws InputError naming the scene key for settings it cannot render (before the device
  // starts; what needs the device is checked when it is made). May be empty.
  std::function<void(const Scene&)> check;
  // Whether its pixels of `scene` depend on the render setting `key` (scene/settings.h): its
  // render key holds those, and the viewer greys out the others.
  std::function<bool(const Scene& scene, const std::string& key)> usesSetting;
};
const EstimatorTraits& estimatorTraits(EstimatorKind kind);

struct EstimatorOptions {
  int batch = 4;  // the path tracer: samples per pixel between progress reports in renderFrame
  // Compiles the kernel benchmark's counters into the walk (FeatureSet::kernelCounters; read
  // with GpuVolumeResources::kernelCounters). Only `plume bench --kernels` sets it.
  bool kernelCounters = false;
};

class Estimator {
 public:
  using SamplesDone = std::function<void(int)>;
  virtual ~Estimator() = default;

  // For the viewer's panel, e.g. "path tracer [sun+env+multi]".
  virtual std::string name() const = 0;
  // The volume of the frame about to be rendered and, for temporal reuse, the previous frame's
  // (null: the current one stands in, e.g. a grid held still). Both must stay alive until the
  // next call.
  virtual void setVolumes(const GpuVolumeResources& current, const GpuVolumeResources* previous) = 0;
  // The next frame starts without history: the frame before it was not rendered in this run, or
  // an edit broke continuity. Nothing to do for estimators whose frames are independent.
  virtual void forgetHistory() {}

  // A finished frame (plume render, plume bench): `spp` samples per pixel of `frame` (ReSTIR:
  // iterations, their random streams keyed by the iteration within the frame; the first eighth
  // settle and are not averaged); samplesDone(n) after every n when given.
  virtual void renderFrame(int frame, int spp, const SamplesDone& samplesDone) = 0;
  // Progressive (plume view): beginFrame clears the accumulation, addSamples(n) adds n samples
  // per pixel (ReSTIR: n iterations, their random streams running on across frames).
  virtual void beginFrame(int frame) = 0;
  virtual void addSamples(int n) = 0;
  virtual int samplesSoFar() const = 0;

  virtual Image readImage() const = 0;  // mean + variance of the mean
  // The accumulation on the device (render/gpu_scene.h readAccumulation's layout), for a display
  // pass that reads it in place.
  virtual const gpu::Buffer& accumulation() const = 0;
  virtual const PassTimes& lastPassTimes() const = 0;

  // The frame's render key (scene/render_key.h) as far as the estimator knows it.
  virtual RenderKey renderKey(int frame) const = 0;
  // Header entries: variant, the estimator's settings, the last frame's timings and counters.
  virtual void describe(std::map<std::string, std::string>& meta) const = 0;
  // The last frame's timings and counters for its log line.
  virtual std::string detail() const = 0;
};

// The estimator of `kind` for `scene`, which must outlive it (it reads camera, media and settings
// at every frame).
std::unique_ptr<Estimator> makeEstimator(EstimatorKind kind, gpu::Context& ctx, gpu::ShaderCompiler& compiler,
                                         const Scene& scene, const EstimatorOptions& options = {});

// "name 1.23 ms, name 4.56 ms" for headers and log lines.
std::string passTimesText(const PassTimes& times);

}  // namespace plume
