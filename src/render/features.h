// What the GPU estimators share about a scene and a pass: the feature set their shaders are
// compiled for (DESIGN §5) and the per-pass GPU times they report.
#pragma once

#include "gpu/shader_compiler.h"
#include "scene/scene.h"

#include <string>
#include <utility>
#include <vector>

namespace plume {

// What a scene needs compiled in (DESIGN §5): light types present, multiple bounces.
// (Whether tracking skips empty space is a property of the volume: see PathTracer::setVolume.)
struct FeatureSet {
  // environment: any environment light (a constant one or a map); envMap: one with a map.
  bool sun = false, point = false, environment = false, envMap = false, multiBounce = false;
  bool emission = false, blackbody = false;  // the medium emits (blackbody: its colour form)
  bool surfaces = false, emitters = false;   // the scene has surfaces (emitters: some emit)
  // The grids are read through the texture unit's trilinear filter (volume/grid.glsl), not with
  // exact weights: render.density_filter biased-hardware, or auto on a device whose filter is
  // measured exact (render/filter_probe.h). Set by the estimators, which hold the device.
  bool hardwareFilter = false;
  // The kernel benchmark's event counters in the walk (shared/kernel_counters.h): never a scene
  // feature, set only by `plume bench --kernels` (EstimatorOptions::kernelCounters).
  bool kernelCounters = false;
  // The surfaces' BVH depth once it is built (GpuSurfaces::bvhStats): the traversal stack's
  // entries, compiled in as PLUME_BVH_STACK (surface/bvh.glsl); 0: not built.
  int bvhStack = 0;
  gpu::ShaderDefines defines() const;
  std::string name() const;  // e.g. "sun+env+multi", "env+envmap"
};
FeatureSet featuresOf(const Scene& scene);

// Per-pass GPU times of the last batch, ms.
using PassTimes = std::vector<std::pair<std::string, double>>;

}  // namespace plume
