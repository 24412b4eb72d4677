// Where every command gets its device volumes (DESIGN §3): the medium's VDB file of a frame,
// loaded and sanitised (media/vdb_loader.h), baked (media/bake.h) and uploaded with the medium's
// density scale (render/gpu_volume.h); the previous frame's volume kept for temporal reuse.
// `plume render`, `plume view` and `plume bench` all load through it.
#pragma once

#include "gpu/context.h"
#include "media/bake.h"
#include "render/gpu_volume.h"
#include "scene/scene.h"

#include <cstdint>
#include <map>
#include <memory>
#include <string>

namespace plume {

struct VolumeSourceOptions {
  BakeOptions bake;
  // Keep the volume of the frame loaded before (previous()): estimators that carry history
  // evaluate it with that frame's grid.
  bool keepPrevious = false;
  // The viewer's way: bakes kept by file (it steps back and forth through a small sequence), and
  // while the file stays the device copy is kept and only its density scale set (the slider).
  bool interactive = false;
};

class VolumeSource {
 public:
  // `medium` must outlive the source; its density scale is read at every load.
  VolumeSource(gpu::Context& ctx, const Medium& medium, const VolumeSourceOptions& options);

  // Makes `frame`'s volume the current one. Each call gives a new volume (GpuVolumeResources
  // serial), even of the same file; the one current before is freed first unless kept as
  // previous().
  const GpuVolumeResources& load(int frame);
  // With keepPrevious: the volume of frame - 1 when that was the last one loaded, else null.
  const GpuVolumeResources* previous() const;
  // Values of the current frame's grids (density, and emission if used) that were NaN, infinite or
  // negative and replaced by 0.
  uint64_t replacedValues() const { return replacedValues_; }

 private:
  struct Bake {
    BakedVolume volume;
    uint64_t replacedValues = 0;
  };
  Bake bakeFile(const std::string& path) const;
  const Emission* emission() const { return medium_.emission ? &*medium_.emission : nullptr; }

  gpu::Context& ctx_;
  const Medium& medium_;
  VolumeSourceOptions options_;
  std::map<std::string, Bake> bakes_;  // interactive: by file
  std::unique_ptr<GpuVolumeResources> current_, previous_;
  std::string currentPath_;
  int currentFrame_ = 0, previousFrame_ = 0;
  uint64_t replacedValues_ = 0;
};

}  // namespace plume
