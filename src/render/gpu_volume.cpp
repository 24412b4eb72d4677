#include "render/gpu_volume.h"

#include "core/blackbody.h"
#include "core/error.h"
#include "core/log.h"

#include <atomic>
#include <algorithm>

namespace plume {

namespace {
uint64_t newSerial() {
  static std::atomic<uint64_t> next{1};
  return next++;
}
}  // namespace

GpuVolumeResources::GpuVolumeResources(gpu::Context& ctx, const BakedVolume& bake, float densityScale,
                                       const Emission* emission) {
  serial_ = newSerial();
  using namespace shared;
  const bool empty = bake.empty();
  params_.worldToIndex = bake.worldToIndex;
  params_.indexToWorld = bake.indexToWorld;
  params_.brickOrigin = bake.brickOrigin;
  params_.empty = empty ? 1 : 0;
  params_.brickDims = bake.brickDims;
  params_.texelFormat = int(bake.format);
  params_.atlasSlots = bake.atlasSlots;
  params_.boundsMin = bake.indexBoundsMin;
  params_.densityScale = densityScale;
  params_.boundsMax = bake.indexBoundsMax;
  const size_t levels = std::min<size_t>(bake.maxLevels.size(), GPU_MAX_LEVELS);
  std::vector<float> majorants;
  for (size_t k = 0; k < levels; ++k) {
    const MaxLevel& L = bake.maxLevels[k];
    params_.levels[k].cells = L.dims;
    params_.levels[k].bricksPerCell = L.cellBricks;
    params_.levelOffset[int(k)] = uint32_t(majorants.size());
    majorants.insert(majorants.end(), L.max.begin(), L.max.end());
  }
  if (!empty && (levels == 0 || bake.maxLevels[0].dims != bake.brickDims)) {
    throw InternalError("bake: level 0 of the majorant hierarchy must match the indirection grid");
  }
  params_.levelCount = uint32_t(levels);
  // The footprint: a lookup inside a cell of level k reads at most the cell's majorant (its max
  // over the texels its lookups read), so the density is 0 outside the cells whose majorant is
  // not. Cell c of level k covers the bricks brickOrigin + c * cellBricks + [0, cellBricks)³,
  // index-space points [8 b, 8 b + 8) of brick b (shaders/volume/grid.glsl vol_locate).
  footprint_.bounds = {bake.indexBoundsMin, bake.indexBoundsMax};
  footprint_.indexToWorld = params_.indexToWorld;
  footprint_.empty = empty;
  for (const MaxLevel& L : bake.maxLevels) {
    const size_t occupied = size_t(std::count_if(L.max.begin(), L.max.end(), [](float m) { return m > 0.0f; }));
    if (occupied > kFootprintCells) continue;
    const float side = float(kBrickVoxels * L.cellBricks);
    const glm::vec3 origin = glm::vec3(bake.brickOrigin * kBrickVoxels);
    for (int z = 0; z < L.dims.z; ++z)
      for (int y = 0; y < L.dims.y; ++y)
        for (int x = 0; x < L.dims.x; ++x) {
          if (!(L.max[(size_t(z) * L.dims.y + y) * L.dims.x + x] > 0.0f)) continue;
          const glm::vec3 lo = origin + side * glm::vec3(x, y, z);
          footprint_.cells.push_back({lo, lo + side});
        }
    break;
  }

  const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  paramBuffer_ = gpu::Buffer(ctx, sizeof(params_), storage, "volume parameters");
  paramBuffer_.upload(&params_, sizeof(params_));

  const bool f16 = bake.format == TexelFormat::Float16;
  atlas_ = gpu::Image3D(ctx, bake.atlasTexels, f16 ? VK_FORMAT_R16_SFLOAT : VK_FORMAT_R32_SFLOAT,
                        f16 ? 2 : 4, "brick atlas");
  const size_t atlasBytes = f16 ? bake.atlasF16.size() * 2 : bake.atlasF32.size() * 4;
  atlas_.upload(f16 ? (const void*)bake.atlasF16.data() : (const void*)bake.atlasF32.data(), atlasBytes);

  // Slot indices become packed slot coordinates (x | y << 10 | z << 20): no division in shaders.
  if (glm::any(glm::greaterThan(bake.atlasSlots, glm::ivec3(1024)))) {
    // Unreachable with the bake's default layout (BakeOptions::maxAtlasSlotsPerAxis, which makes
    // larger volumes an InputError naming the file): a bake configured past the packing.
    throw InternalError(strf("bake: %dx%dx%d atlas slots; the packed slot coordinates hold at most 1024 per axis",
                             bake.atlasSlots.x, bake.atlasSlots.y, bake.atlasSlots.z));
  }
  std::vector<uint32_t> packed(bake.indirection.size());
  for (size_t i = 0; i < packed.size(); ++i) {
    const glm::ivec3 o = slotTexelOrigin(bake, bake.indirection[i]) / kBrickTexels;
    packed[i] = uint32_t(o.x) | uint32_t(o.y) << 10 | uint32_t(o.z) << 20;
  }
  indirection_ = gpu::TexelBuffer(ctx, packed.data(), packed.size(), VK_FORMAT_R32_UINT, "brick indirection");
  majorants_ = gpu::TexelBuffer(ctx, majorants.data(), majorants.size(), VK_FORMAT_R32_SFLOAT, "majorant hierarchy");
  // Per atlas slot 512 words: each voxel's mean and residual bound as two float16
  // (bake.h packedMeanField; volume/walk.glsl).
  std::vector<uint32_t> coarse = packedMeanField(bake);
  // Baked without it (a path-traced render): a placeholder, so that binding sets stay valid.
  hasMeanField_ = !coarse.empty();
  if (coarse.empty()) coarse.assign(4, 0u);
  coarse_ = gpu::TexelBuffer(ctx, coarse.data(), coarse.size(), VK_FORMAT_R32_UINT, "mean field");
  counters_ = gpu::Buffer(ctx, shared::KC_WORDS * 4, storage, "tracking counters");
  resetCounters();
  bytes_ = sizeof(params_) + atlasBytes + bake.indirection.size() * 4 + majorants.size() * 4 + coarse.size() * 4;

  if (bake.hasEmission() != (emission != nullptr)) {
    throw InternalError("volume upload: the bake's emission channel and the medium's emission settings disagree");
  }
  if (emission) {
    hasEmission_ = true;
    params_.emission = emission->blackbody ? EMISSION_BLACKBODY : EMISSION_COLOR;
    params_.emissionScale = emission->blackbody ? glm::vec3(emission->scale) : emission->scale * emission->color;
    params_.temperatureScale = emission->temperatureScale;
    params_.temperatureOffset = emission->temperatureOffset;
    paramBuffer_.upload(&params_, sizeof(params_));
    emissionAtlas_ = gpu::Image3D(ctx, bake.atlasTexels, VK_FORMAT_R32_SFLOAT, 4, "emission atlas");
    emissionAtlas_.upload(bake.emissionF32.data(), bake.emissionF32.size() * 4);
    // The same for every volume: integrated once per process (4096 spectral integrals), not per frame.
    static const std::vector<glm::vec4> table = blackbodyTable();
    blackbody_ = gpu::TexelBuffer(ctx, table.data(), table.size(), VK_FORMAT_R32G32B32A32_SFLOAT, "blackbody table");
    bytes_ += bake.emissionF32.size() * 4 + table.size() * sizeof(glm::vec4);
  }
}

void GpuVolumeResources::setDensityScale(float densityScale) {
  if (params_.densityScale == densityScale) return;
  params_.densityScale = densityScale;
  paramBuffer_.upload(&params_, sizeof(params_));
  serial_ = newSerial();  // another medium: renderers must not take it for the one they rendered
}

gpu::BindingTypes GpuVolumeResources::bindingTypes(bool restir, bool emission) {
  using gpu::BindingType;
  using namespace shared;
  gpu::BindingTypes t = {{BIND_ATLAS, BindingType::SampledImage},
                         {BIND_INDIRECTION, BindingType::TexelBuffer},
                         {BIND_MAJORANTS, BindingType::TexelBuffer}};
  if (restir) {
    t.insert(t.end(), {{BIND_MEAN_FIELD, BindingType::TexelBuffer},
                       {BIND_PREV_ATLAS, BindingType::SampledImage},
                       {BIND_PREV_INDIRECTION, BindingType::TexelBuffer},
                       {BIND_PREV_MEAN_FIELD, BindingType::TexelBuffer}});
  }
  if (emission) {
    t.insert(t.end(), {{BIND_EMISSION_ATLAS, BindingType::SampledImage}, {BIND_BLACKBODY, BindingType::TexelBuffer}});
    if (restir) t.push_back({BIND_PREV_EMISSION_ATLAS, BindingType::SampledImage});
  }
  return t;
}

void GpuVolumeResources::bind(gpu::DescriptorSet& set) const {
  set.bind(shared::BIND_VOLUME, paramBuffer_);
  set.bind(shared::BIND_ATLAS, atlas_);
  set.bind(shared::BIND_INDIRECTION, indirection_);
  set.bind(shared::BIND_MAJORANTS, majorants_);
  set.bind(shared::BIND_VOLUME_COUNTERS, counters_);
  if (hasEmission_) {
    set.bind(shared::BIND_EMISSION_ATLAS, emissionAtlas_);
    set.bind(shared::BIND_BLACKBODY, blackbody_);
  }
}

void GpuVolumeResources::requireLinearFilter() const {
  const bool ok = atlas_.linearFilter() && (!hasEmission_ || emissionAtlas_.linearFilter());
  if (!ok) {
    throw InputError(std::string("render.density_filter: biased-hardware: the device cannot filter the ") +
                     (atlas_.linearFilter() ? "emission atlas (R32F)" : "brick atlas") +
                     " linearly; use auto (the default) or exact");
  }
}

void GpuVolumeResources::bindMeanField(gpu::DescriptorSet& set) const { set.bind(shared::BIND_MEAN_FIELD, coarse_); }

void GpuVolumeResources::bindAsPrevious(gpu::DescriptorSet& set) const {
  set.bind(shared::BIND_PREV_VOLUME, paramBuffer_);
  set.bind(shared::BIND_PREV_ATLAS, atlas_);
  set.bind(shared::BIND_PREV_INDIRECTION, indirection_);
  set.bind(shared::BIND_PREV_MEAN_FIELD, coarse_);
  if (hasEmission_) set.bind(shared::BIND_PREV_EMISSION_ATLAS, emissionAtlas_);
}

uint32_t GpuVolumeResources::truncatedCount() const {
  uint32_t c[4];
  counters_.download(c, sizeof c);
  return c[0];
}

uint32_t GpuVolumeResources::loopLimitCount() const {
  uint32_t c[4];
  counters_.download(c, sizeof c);
  return c[1];
}

std::vector<uint32_t> GpuVolumeResources::counterWords() const {
  std::vector<uint32_t> words(shared::KC_WORDS);
  counters_.download(words.data(), words.size() * 4);
  return words;
}

void GpuVolumeResources::resetCounters() {
  const std::vector<uint32_t> zero(shared::KC_WORDS, 0u);
  counters_.upload(zero.data(), zero.size() * 4);
}

}  // namespace plume
