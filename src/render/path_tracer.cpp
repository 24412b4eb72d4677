#include "render/path_tracer.h"

#include "core/error.h"
#include "core/log.h"
#include "render/gpu_scene.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>

namespace plume {

PathTracer::PathTracer(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const Scene& scene, bool kernelCounters)
    : ctx_(ctx), scene_(scene), features_(featuresOf(scene)), compiler_(compiler), timer_(ctx) {
  features_.kernelCounters = kernelCounters;
  checkGpuSupports(scene, "the GPU path tracer");
  envMap_ = std::make_unique<GpuEnvironmentMap>(ctx, scene);
  const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  const size_t pixels = size_t(scene.camera.width) * scene.camera.height;
  frameBuffer_ = gpu::Buffer(ctx, sizeof(shared::GpuFrame), storage, "frame parameters");
  std::vector<shared::GpuLight> lights = gpuLights(scene);
  lightBuffer_ = gpu::Buffer(ctx, lights.size() * sizeof(shared::GpuLight), storage, "lights");
  lightBuffer_.upload(lights.data(), lights.size() * sizeof(shared::GpuLight));
  accum_ = gpu::Buffer(ctx, pixels * 2 * sizeof(glm::vec4), storage, "accumulation");
  pass_ = &makePass(false);
}

gpu::ComputePass& PathTracer::makePass(bool skipEmpty) {
  std::unique_ptr<gpu::ComputePass>& pass = passes_[skipEmpty ? 1 : 0];
  if (pass) return *pass;
  using gpu::BindingType;
  gpu::ShaderDefines defines = features_.defines();
  // Every sampled image in a table must be written before a dispatch (lavapipe reads them all):
  // the emission atlas is in the table of an emitting scene only.
  if (skipEmpty) defines.emplace_back("PLUME_SKIP_EMPTY", "1");
  pass = std::make_unique<gpu::ComputePass>(
      ctx_, compiler_.compile("passes/pt.comp", defines),
      features_.emission
          ? gpu::bindingTable(shared::BIND_BLACKBODY + 1, {{shared::BIND_ATLAS, BindingType::SampledImage},
                                                            {shared::BIND_EMISSION_ATLAS, BindingType::SampledImage}})
          : gpu::bindingTable(shared::BIND_ENV_MAP + 1, {{shared::BIND_ATLAS, BindingType::SampledImage}}),
      sizeof(uint32_t),  // the push constant: this dispatch's sample (addSamples)
      "path tracing [" + features_.name() + (skipEmpty ? "+skip" : "") + "]", glm::uvec3(8, 8, 1));
  pass->set.bind(shared::BIND_FRAME, frameBuffer_);
  pass->set.bind(shared::BIND_LIGHTS, lightBuffer_);
  pass->set.bind(shared::BIND_PT_ACCUM, accum_);
  envMap_->bind(pass->set);
  return *pass;
}

std::string PathTracer::variantName() const { return features_.name() + (skipEmpty_ ? "+skip" : ""); }

void PathTracer::setVolume(const GpuVolumeResources& volume) {
  // Skipping pays when rays cross many bricks: a brick grid wider than 16 on some axis.
  const shared::GpuVolume& p = volume.params();
  const int widest = std::max(p.brickDims.x, std::max(p.brickDims.y, p.brickDims.z));
  skipEmpty_ = p.levelCount >= 2u && widest > 16;
  pass_ = &makePass(skipEmpty_);
  volume.bind(pass_->set);
}

void PathTracer::beginFrame(int frame) {
  frame_ = gpuFrame(scene_, frame, uint32_t(scene_.render.seed), uint32_t(frame), 0u);
  accum_.fillZero();
  samples_ = 0;
}

// One dispatch per sample per pixel: llvmpipe (lavapipe) gives every shader invocation a budget
// of 65535 loop iterations, all loops and all samples of the dispatch together, and past it ends
// every loop after one iteration without a word (volume/loop_guard.glsl); a dispatch of many
// samples spent it in dense media and biased the image low. The dispatches of up to
// kDispatchesPerSubmit samples share one submission (a push constant tells each its sample), and
// their times are summed.
void PathTracer::addSamples(int spp) {
  constexpr int kDispatchesPerSubmit = 16;  // GpuTimer holds 32 scopes
  frame_.spp = 1u;
  frame_.firstSample = uint32_t(samples_);
  frameBuffer_.upload(&frame_, sizeof(frame_));
  const glm::uvec3 items(uint32_t(scene_.camera.width), uint32_t(scene_.camera.height), 1u);
  passTimes_.clear();
  for (int done = 0; done < spp;) {
    const int n = std::min(spp - done, kDispatchesPerSubmit);
    ctx_.submitAndWait([&](VkCommandBuffer cmd) {
      timer_.reset(cmd);
      for (int i = 0; i < n; ++i) {
        if (i > 0) gpu::computeBarrier(cmd);
        const uint32_t sampleOffset = uint32_t(done + i);
        pass_->record(cmd, items, &sampleOffset, &timer_);
      }
    });
    for (const auto& [name, ms] : timer_.read()) {
      auto it = std::find_if(passTimes_.begin(), passTimes_.end(), [&](const auto& p) { return p.first == name; });
      if (it == passTimes_.end()) {
        passTimes_.emplace_back(name, ms);
      } else {
        it->second += ms;
      }
    }
    done += n;
  }
  samples_ += spp;
}

Image PathTracer::readImage() const { return readAccumulation(accum_, scene_.camera.width, scene_.camera.height); }

}  // namespace plume
