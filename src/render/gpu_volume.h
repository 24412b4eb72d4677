// The baked volume on the device (DESIGN §3): the brick atlas as a 3D texture (R16F or R32F),
// the indirection and the majorant hierarchy as texel buffers, ReSTIR's voxel mean field, and
// the GpuVolume parameter block. Bound by the names of shaders/shared/bindings.h
// (shaders/volume/bindings.glsl).
#pragma once

#include "gpu/pipeline.h"
#include "gpu/resources.h"
#include "media/bake.h"
#include "render/pixel_order.h"
#include "scene/scene.h"
#include "shaders/shared/bindings.h"
#include "shaders/shared/gpu_types.h"
#include "shaders/shared/kernel_counters.h"

#include <vector>

namespace plume {

class GpuVolumeResources {
 public:
  // `emission`: the medium's emission settings, required when the bake has an emission channel.
  GpuVolumeResources(gpu::Context& ctx, const BakedVolume& bake, float densityScale,
                     const Emission* emission = nullptr);

  // Binds params, atlas, indirection, majorants and counters (BIND_VOLUME .. BIND_VOLUME_COUNTERS),
  // and with an emission channel the emission atlas and the blackbody table (BIND_EMISSION_ATLAS,
  // BIND_BLACKBODY).
  void bind(gpu::DescriptorSet& set) const;
  // The descriptor types of the volume's bindings in a pass's table (the rest, the parameter
  // blocks among them, are storage buffers): the atlases sampled images, the indirections, the
  // majorants, the mean fields and the blackbody table uniform texel buffers (lanes read them at
  // places of their own in the walks' loops: docs/architecture.md, "Descriptor kinds").
  // `restir`: with the mean field and the previous frame's volume (shaders/restir/bindings.glsl);
  // `emission`: with the emission.
  static gpu::BindingTypes bindingTypes(bool restir, bool emission);
  // Binds ReSTIR's mean field (BIND_MEAN_FIELD): 512 words per atlas slot (slot index
  // x + X * (y + Y * z) of the packed slot coordinates), each voxel's mean and residual bound as
  // two float16 (bake.h packedMeanField).
  void bindMeanField(gpu::DescriptorSet& set) const;
  // Binds this volume as ReSTIR's previous-frame volume (BIND_PREV_*).
  void bindAsPrevious(gpu::DescriptorSet& set) const;
  const shared::GpuVolume& params() const { return params_; }
  // Where the density may be non-zero (render/pixel_order.h): the bounds and the non-zero cells of
  // the finest level of the majorant hierarchy that has at most kFootprintCells of them.
  const VolumeFootprint& footprint() const { return footprint_; }
  static constexpr size_t kFootprintCells = 4096;
  // For render.density_filter = biased-hardware (shaders read the atlases with texture()): throws
  // InputError, naming the setting, where the device cannot filter the atlases' formats linearly.
  void requireLinearFilter() const;
  // Changes the density scale in place (one small upload; the atlas and fields stay). The volume
  // then counts as a new one (serial). Not while a submitted pass still reads it.
  void setDensityScale(float densityScale);
  uint64_t deviceBytes() const { return bytes_; }
  bool hasMeanField() const { return hasMeanField_; }  // ReSTIR needs it (BakeOptions::meanField)
  // Unique per constructed volume in this process (never reused), so a renderer can tell that
  // the volume it rendered last frame is the one it is given now.
  uint64_t serial() const { return serial_; }

  // Tracking loops truncated by the step cap since the last reset (no silent caps).
  uint32_t truncatedCount() const;
  // Shader invocations whose loops the Vulkan driver cut (llvmpipe's shared loop limit:
  // volume/loop_guard.glsl); any is a biased image.
  uint32_t loopLimitCount() const;
  // The whole counter buffer (shared::KC_WORDS words): after the volume's own, the kernel
  // benchmark's counters (shared/kernel_counters.h; zero unless a pass compiled them in).
  std::vector<uint32_t> counterWords() const;
  void resetCounters();

 private:
  shared::GpuVolume params_{};
  VolumeFootprint footprint_;
  bool hasMeanField_ = false;
  gpu::Buffer paramBuffer_;
  gpu::Image3D atlas_;
  gpu::TexelBuffer indirection_;
  gpu::TexelBuffer majorants_;
  gpu::Buffer counters_;
  gpu::TexelBuffer coarse_;
  gpu::Image3D emissionAtlas_;  // with an emission channel only
  gpu::TexelBuffer blackbody_;
  bool hasEmission_ = false;
  uint64_t bytes_ = 0;
  uint64_t serial_ = 0;
};

}  // namespace plume
