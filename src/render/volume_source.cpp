#include "render/volume_source.h"

#include "core/log.h"
#include "media/vdb_loader.h"

namespace plume {

VolumeSource::VolumeSource(gpu::Context& ctx, const Medium& medium, const VolumeSourceOptions& options)
    : ctx_(ctx), medium_(medium), options_(options) {}

VolumeSource::Bake VolumeSource::bakeFile(const std::string& path) const {
  LoadedGrid grid = loadFloatGrid(path, medium_.densityGrid);
  if (grid.replacedValues > 0) {
    logWarn(strf("%s: %llu NaN, infinite or negative values replaced by 0", grid.path.c_str(),
                 (unsigned long long)grid.replacedValues));
  }
  grid.clampedValues = clampOpticalDepth(*grid.grid, medium_.densityScale);
  if (grid.clampedValues > 0) warnClamped(grid, medium_.densityScale);
  Bake bake{bakeVolume(grid, options_.bake), grid.replacedValues};
  if (medium_.emission) {  // only a grid the scene uses is loaded
    LoadedGrid emission = loadFloatGrid(path, medium_.emission->grid);
    if (emission.replacedValues > 0) {
      logWarn(strf("%s: grid \"%s\": %llu NaN, infinite or negative values replaced by 0", emission.path.c_str(),
                   emission.name.c_str(), (unsigned long long)emission.replacedValues));
    }
    bakeEmission(bake.volume, grid, emission);
    bake.replacedValues += emission.replacedValues;
  }
  return bake;
}

const GpuVolumeResources& VolumeSource::load(int frame) {
  const std::string path = medium_.vdbPath(frame);
  if (options_.interactive && current_ && path == currentPath_) {
    current_->setDensityScale(medium_.densityScale);  // no re-upload of the grid
  } else {
    previousFrame_ = currentFrame_;
    previous_ = options_.keepPrevious ? std::move(current_) : nullptr;
    current_.reset();  // free the old device copy before making the new one
    if (options_.interactive) {
      auto it = bakes_.find(path);  // a still volume is baked once
      if (it == bakes_.end()) it = bakes_.emplace(path, bakeFile(path)).first;
      current_ = std::make_unique<GpuVolumeResources>(ctx_, it->second.volume, medium_.densityScale, emission());
      replacedValues_ = it->second.replacedValues;
    } else {
      const Bake bake = bakeFile(path);
      current_ = std::make_unique<GpuVolumeResources>(ctx_, bake.volume, medium_.densityScale, emission());
      replacedValues_ = bake.replacedValues;
    }
    currentPath_ = path;
  }
  currentFrame_ = frame;
  return *current_;
}

const GpuVolumeResources* VolumeSource::previous() const {
  return previous_ && previousFrame_ == currentFrame_ - 1 ? previous_.get() : nullptr;
}

}  // namespace plume
