#include "render/path_tracer.h"

#include "core/error.h"
#include "core/log.h"
#include "render/filter_probe.h"
#include "render/gpu_scene.h"
#include "shaders/shared/pt_wave.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace plume {

namespace {
constexpr uint32_t kBouncesPerSubmit = 16;  // extension + shading rounds recorded per submission
}  // namespace

PathTracer::PathTracer(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const Scene& scene, bool kernelCounters,
                       VkDeviceSize bufferLimit)
    : ctx_(ctx), scene_(scene), features_(featuresOf(scene)), compiler_(compiler),
      timer_(ctx, 2 * kBouncesPerSubmit + 1) {
  features_.kernelCounters = kernelCounters;
  features_.hardwareFilter = useHardwareFilter(ctx, compiler, scene.render.densityFilter);  // render/filter_probe.h
  envMap_ = std::make_unique<GpuEnvironmentMap>(ctx, scene);
  if (features_.surfaces) {
    surfaces_ = std::make_unique<GpuSurfaces>(ctx, scene);
    features_.bvhStack = surfaces_->bvhStats().depth;
  }
  const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  const size_t pixels = size_t(scene.camera.width) * scene.camera.height;
  frameBuffer_ = gpu::Buffer(ctx, sizeof(shared::GpuFrame), storage, "frame parameters");
  std::vector<shared::GpuLight> lights = gpuLights(scene);
  lightBuffer_ = lightTexels(ctx, lights);
  // Whole samples of every pixel per generation, about kGenerationPaths paths, so that a small
  // image's samples share the rounds' dispatches and the resolve; a larger image goes in bands of
  // kGenerationPaths pixels with up to kMaxSlots / kGenerationPaths samples each (one sample per
  // band of kMaxSlots pixels, until session 25, cost its resolve ~43 ns a pixel and sample on
  // lavapipe, ~20% of a 1024² frame; four per band amortise the resolve's invocations).
  // The slots are a storage texel buffer of PT_PATH_TEXELS texels each: fewer of them where the
  // device allows fewer texels (Vulkan's minimum, 65536 texels, holds 13107; lavapipe 2^27).
  const uint32_t maxSlots = std::min<uint32_t>(kMaxSlots, ctx.limits().maxTexelBufferElements / shared::PT_PATH_TEXELS);
  const uint32_t generationPaths = std::min(kGenerationPaths, maxSlots);
  if (pixels <= generationPaths) {
    bandPixels_ = uint32_t(std::max<size_t>(pixels, 1));
    slots_ = uint32_t(std::max<size_t>(1, generationPaths / bandPixels_) * bandPixels_);
  } else {
    bandPixels_ = generationPaths;
    slots_ = maxSlots / generationPaths * generationPaths;
  }
  // The accumulation (32 bytes a pixel) in as few buffers as the device's largest storage buffer
  // allows (lavapipe: 128 MiB, 4.2 megapixels; a 3840x2160 image needs two), each a whole number
  // of generation bands, so that a generation's pixels lie in one buffer.
  const VkDeviceSize limit = bufferLimit > 0 ? bufferLimit : ctx.limits().maxStorageBufferRange;
  constexpr VkDeviceSize kAccumBytes = 2 * sizeof(glm::vec4);
  const VkDeviceSize bandsPerBuffer = limit / (kAccumBytes * bandPixels_);
  if (bandsPerBuffer == 0) {
    throw InputError(strf("%s: the path tracer's accumulation band of %u pixels needs %.1f MiB, more than the "
                          "device's storage buffer limit of %.1f MiB", ctx.deviceName().c_str(), bandPixels_,
                          double(bandPixels_ * kAccumBytes) / 1048576.0, double(limit) / 1048576.0));
  }
  accumPixels_ = uint32_t(std::min<VkDeviceSize>(bandsPerBuffer * bandPixels_, std::max<size_t>(pixels, 1)));
  for (size_t begin = 0; begin < std::max<size_t>(pixels, 1); begin += accumPixels_) {
    const size_t n = std::min<size_t>(accumPixels_, pixels - begin);
    accums_.emplace_back(ctx, std::max<size_t>(n, 1) * kAccumBytes, storage,
                         n == pixels ? std::string("accumulation") : strf("accumulation part %zu", accums_.size()));
  }
  paths_ = gpu::TexelBuffer(ctx, nullptr, size_t(slots_) * shared::PT_PATH_TEXELS, VK_FORMAT_R32G32B32A32_UINT,
                           "path slots", true, true);
  queues_ = gpu::Buffer(ctx, size_t(slots_) * 2 * sizeof(uint32_t), storage, "path queues");
  wave_ = gpu::Buffer(ctx, sizeof(shared::PtWave), storage | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT, "path queue lengths");
  // The pixel list, ordered by each frame's first addSamples (orderPixels); only with the
  // background pass (an image of one accumulation buffer, far below the texel limit).
  const bool background = !features_.surfaces && accums_.size() == 1;
  pixelList_ = gpu::TexelBuffer(ctx, nullptr, background ? std::max<size_t>(pixels, 1) : 1, VK_FORMAT_R32_UINT,
                                "pixel list");
  const gpu::ShaderDefines none;
  queue_ = makePass("passes/pt_queue.comp", none, "pt queues", false);
  for (const gpu::Buffer& band : accums_) {
    resolves_.push_back(makePass("passes/pt_resolve.comp", none, "pt resolve", false));
    resolves_.back()->set.bind(shared::BIND_PT_ACCUM, band);
  }
  // The background pass: a camera ray that can only miss sees the environment; with surfaces
  // every ray may meet the scene. One accumulation buffer only (a split one keeps its bands in
  // row order: path_tracer.h orderPixels).
  if (background) background_ = makePass("passes/pt_background.comp", features_.defines(), "pt background", true);
  active_ = &tracking(false);
}

// The descriptor types of the kernels that walk the scene (the rest are storage buffers).
gpu::BindingTypes PathTracer::volumeTypes() const {
  gpu::BindingTypes types = sceneBindingTypes(false, features_.emission, features_.surfaces, 0);
  types.emplace_back(shared::BIND_PT_PATH_TEXELS, gpu::BindingType::TexelBuffer);
  types.emplace_back(shared::BIND_PT_PIXELS, gpu::BindingType::TexelBuffer);
  return types;
}

std::unique_ptr<gpu::ComputePass> PathTracer::makePass(const std::string& file, const gpu::ShaderDefines& defines,
                                                       const std::string& name, bool volumeTable) {
  using gpu::BindingType;
  gpu::ShaderDefines all = defines;
  if (!ctx_.subgroupBallot()) all.emplace_back("PLUME_NO_SUBGROUP_BALLOT", "1");
  // Every sampled image in a table must be written before a dispatch (lavapipe reads them all):
  // the volume's images are in the tables of the kernels that walk it, the emission atlas only
  // where the scene emits.
  std::vector<BindingType> table =
      !volumeTable ? gpu::bindingTable(shared::BIND_PT_PIXELS + 1,
                                       {{shared::BIND_PT_PATH_TEXELS, gpu::BindingType::TexelBuffer},
                                        {shared::BIND_PT_PIXELS, gpu::BindingType::TexelBuffer}})
      : gpu::bindingTable(features_.emission ? shared::BIND_BLACKBODY + 1 : shared::BIND_ENV_MAP + 1, volumeTypes());
  auto pass = std::make_unique<gpu::ComputePass>(ctx_, compiler_.compile(file, all), std::move(table),
                                                 uint32_t(sizeof(shared::PtPush)), name,
                                                 glm::uvec3(shared::PT_WAVE_GROUP, 1, 1));
  pass->set.bind(shared::BIND_FRAME, frameBuffer_);
  pass->set.bind(shared::BIND_PT_ACCUM, accums_[0]);  // the resolve passes rebind their band
  pass->set.bind(shared::BIND_PT_PATHS, paths_.buffer());
  pass->set.bind(shared::BIND_PT_PATH_TEXELS, paths_);
  pass->set.bind(shared::BIND_PT_PIXELS, pixelList_);
  pass->set.bind(shared::BIND_PT_QUEUES, queues_);
  pass->set.bind(shared::BIND_PT_WAVE, wave_);
  if (volumeTable) {
    pass->set.bind(shared::BIND_LIGHTS, lightBuffer_);
    envMap_->bind(pass->set);
    if (surfaces_) surfaces_->bind(pass->set);
  }
  return pass;
}

PathTracer::Tracking& PathTracer::tracking(bool skipEmpty) {
  Tracking& t = tracking_[skipEmpty ? 1 : 0];
  if (t.extend) return t;
  gpu::ShaderDefines defines = features_.defines();
  if (skipEmpty) defines.emplace_back("PLUME_SKIP_EMPTY", "1");
  const std::string variant = "[" + features_.name() + (skipEmpty ? "+skip" : "") + "]";
  t.camera = makePass("passes/pt_camera.comp", defines, "pt camera " + variant, true);
  t.extend = makePass("passes/pt_extend.comp", defines, "pt extend " + variant, true);
  t.shade = makePass("passes/pt_shade.comp", defines, "pt shade " + variant, true);
  return t;
}

std::string PathTracer::variantName() const { return features_.name() + (skipEmpty_ ? "+skip" : ""); }

void PathTracer::setVolume(const GpuVolumeResources& volume) {
  if (features_.hardwareFilter) volume.requireLinearFilter();
  // Skipping pays when rays cross many bricks: a brick grid wider than 16 on some axis.
  const shared::GpuVolume& p = volume.params();
  const int widest = std::max(p.brickDims.x, std::max(p.brickDims.y, p.brickDims.z));
  skipEmpty_ = p.levelCount >= 2u && widest > 16;
  active_ = &tracking(skipEmpty_);
  volume.bind(active_->camera->set);
  volume.bind(active_->extend->set);
  volume.bind(active_->shade->set);
  if (background_) volume.bind(background_->set);
  footprint_ = volume.footprint();
  volumeSerial_ = volume.serial();
}

void PathTracer::orderPixels() {
  if (ordered_ && sameCamera(orderCam_, frame_.camera) && orderSerial_ == volumeSerial_) return;
  const int w = scene_.camera.width, h = scene_.camera.height;
  if (background_) {
    order_ = volumePixelOrder(frame_.camera, w, h, footprint_);
    pixelList_.upload(order_.pixels.data(), order_.pixels.size() * sizeof(uint32_t));
  } else {
    order_.pixels.clear();  // row order, all inside: no list (PtPush::listed 0)
    order_.inside = uint32_t(size_t(w) * size_t(h));
  }
  orderCam_ = frame_.camera;
  orderSerial_ = volumeSerial_;
  ordered_ = true;
}

void PathTracer::beginFrame(int frame) {
  frame_ = gpuFrame(scene_, frame, uint32_t(scene_.render.seed), uint32_t(frame));
  for (gpu::Buffer& band : accums_) band.fillZero();
  samples_ = 0;
}

void PathTracer::addTimes() {
  for (const auto& [name, ms] : timer_.read()) {
    auto it = std::find_if(passTimes_.begin(), passTimes_.end(), [&](const auto& p) { return p.first == name; });
    if (it == passTimes_.end()) {
      passTimes_.emplace_back(name, ms);
    } else {
      it->second += ms;
    }
  }
}

// Every path of the generation is extended, its collision shaded, and so on, in rounds recorded
// kBouncesPerSubmit at a time until the extension queue is empty (at most max_bounces + 1
// extensions: a path ends at its (max_bounces + 1)-th collision). Then its samples are merged.
void PathTracer::traceGeneration(uint32_t pixelBegin, uint32_t pixels, uint32_t sampleBase, uint32_t samples) {
  shared::PtPush push{};
  push.pixelBegin = pixelBegin;
  push.pixelCount = pixels;
  push.listed = background_ ? 1u : 0u;
  push.sampleBase = sampleBase;
  push.slots = pixels * samples;
  PLUME_CHECK(push.slots <= slots_);
  const shared::PtWave empty{};
  wave_.upload(&empty, sizeof(empty));
  constexpr VkDeviceSize kExtendArgs = offsetof(shared::PtWave, extendArgs);
  constexpr VkDeviceSize kShadeArgs = offsetof(shared::PtWave, shadeArgs);
  const uint64_t maxExtensions = uint64_t(frame_.maxBounces) + 1u;
  for (uint64_t extensions = 0;;) {
    ctx_.submitAndWait([&](VkCommandBuffer cmd) {
      timer_.reset(cmd);
      if (extensions == 0) {
        // The camera rays: those that may meet the scene are queued for the first extension.
        const uint32_t scope = timer_.begin(cmd, active_->camera->pipeline.name());
        active_->camera->record(cmd, glm::uvec3(push.slots, 1, 1), &push);
        gpu::computeBarrier(cmd);
        push.stage = shared::PT_QUEUE_TO_EXTEND;
        queue_->record(cmd, glm::uvec3(1), &push);
        timer_.end(cmd, scope);
        gpu::computeBarrier(cmd);
      }
      for (uint32_t round = 0; round < kBouncesPerSubmit && extensions < maxExtensions; ++round, ++extensions) {
        // Each kernel is timed with the queue kernel that follows it.
        uint32_t scope = timer_.begin(cmd, active_->extend->pipeline.name());
        push.cameraRays = extensions == 0 ? 1u : 0u;
        active_->extend->recordIndirect(cmd, wave_, kExtendArgs, &push);
        gpu::computeBarrier(cmd);
        push.stage = shared::PT_QUEUE_TO_SHADE;
        queue_->record(cmd, glm::uvec3(1), &push);
        timer_.end(cmd, scope);
        gpu::computeBarrier(cmd);
        scope = timer_.begin(cmd, active_->shade->pipeline.name());
        active_->shade->recordIndirect(cmd, wave_, kShadeArgs, &push);
        gpu::computeBarrier(cmd);
        push.stage = shared::PT_QUEUE_TO_EXTEND;
        queue_->record(cmd, glm::uvec3(1), &push);
        timer_.end(cmd, scope);
        gpu::computeBarrier(cmd);
      }
    });
    addTimes();
    shared::PtWave wave{};
    wave_.download(&wave, sizeof(wave));
    if (wave.extendArgs.w == 0u) break;
    // A path still queued after max_bounces + 1 extensions would be a bug in the kernels.
    PLUME_CHECK_MSG(extensions < maxExtensions, "path tracer: paths left after max_bounces + 1 extensions");
  }
  // The accumulation buffer that holds these pixels, indexed from its first (a split one's list is
  // in row order, so its entries are its pixel indices: orderPixels).
  const uint32_t part = accums_.size() == 1 ? 0u : pixelBegin / accumPixels_;
  PLUME_CHECK(part < accums_.size() && (accums_.size() == 1 || (pixelBegin + pixels - 1) / accumPixels_ == part));
  push.accumBase = part * accumPixels_;
  ctx_.submitAndWait([&](VkCommandBuffer cmd) {
    timer_.reset(cmd);
    resolves_[part]->record(cmd, glm::uvec3(pixels, 1, 1), &push, &timer_);
  });
  addTimes();
}

// Generations of at most kMaxSlots paths: several samples of every pixel where the image is
// small, a band of pixels at a time where it is large. Each path's random stream is its pixel's
// and sample's (DESIGN §2), so the image does not depend on how the samples are grouped.
void PathTracer::addSamples(int spp) {
  frame_.firstSample = uint32_t(samples_);
  frameBuffer_.upload(&frame_, sizeof(frame_));
  orderPixels();
  const uint32_t pixels = order_.inside;
  passTimes_.clear();
  for (uint32_t done = 0; done < uint32_t(spp);) {
    const uint32_t n = std::min(uint32_t(spp) - done, samplesPerGeneration());
    for (uint32_t begin = 0; begin < pixels; begin += bandPixels_) {
      traceGeneration(begin, std::min(bandPixels_, pixels - begin), done, n);
    }
    done += n;
  }
  // The pixels whose every ray misses the scene: their samples in chunks far below the driver's
  // loop budget (volume/loop_guard.glsl), in sample order.
  const uint32_t outside = background_ ? uint32_t(order_.pixels.size()) - order_.inside : 0u;
  if (background_ && outside > 0) {
    constexpr uint32_t kBackgroundSamples = 4096;
    for (uint32_t done = 0; done < uint32_t(spp); done += kBackgroundSamples) {
      shared::PtPush push{};
      push.pixelBegin = order_.inside;
      push.pixelCount = outside;
      push.sampleBase = done;
      push.slots = std::min(kBackgroundSamples, uint32_t(spp) - done);
      push.accumBase = 0;
      push.listed = 1;
      ctx_.submitAndWait([&](VkCommandBuffer cmd) {
        timer_.reset(cmd);
        background_->record(cmd, glm::uvec3(outside, 1, 1), &push, &timer_);
      });
      addTimes();
    }
  }
  samples_ += spp;
}

uint32_t PathTracer::samplesPerGeneration() const { return slots_ / bandPixels_; }

Image PathTracer::readImage() const {
  return readAccumulation(accums_, accumPixels_, scene_.camera.width, scene_.camera.height);
}

const gpu::Buffer& PathTracer::accumulation() const {
  if (accums_.size() != 1) {
    throw InputError(strf("%s: a %dx%d image's accumulation is split into %zu buffers (the device's storage buffer "
                          "limit): the viewer shows images of up to %u pixels on this device",
                          ctx_.deviceName().c_str(), scene_.camera.width, scene_.camera.height, accums_.size(),
                          accumPixels_));
  }
  return accums_[0];
}

}  // namespace plume
