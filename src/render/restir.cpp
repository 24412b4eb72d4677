#include "render/restir.h"

#include "core/error.h"
#include "core/log.h"
#include "render/gpu_scene.h"

#include <glm/glm.hpp>

#include <cmath>

namespace plume {

std::string RestirOptions::name() const {
  const char* kind = mis == shared::RS_MIS_GBH ? "gbh" : mis == shared::RS_MIS_BIASED ? "biased" : "pairwise";
  if (rounds == 0) return strf("restir %s M%d R0 c%d", kind, candidates, historyCap);
  return strf("restir %s M%d k%d r%d R%d c%d", kind, candidates, neighbours, radius, rounds, historyCap);
}

RestirOptions restirOptionsOf(const RenderSettings& rs) {
  RestirOptions o;
  o.candidates = rs.restirCandidates;
  o.neighbours = rs.restirNeighbours;
  o.radius = rs.restirRadius;
  o.rounds = rs.restirRounds;
  o.historyCap = rs.restirHistoryCap;
  o.mis = rs.restirMis == "gbh" ? shared::RS_MIS_GBH : shared::RS_MIS_PAIRWISE;
  return o;
}

namespace {

// The GPU lights with each light's probability of being chosen for a candidate's light sample
// (params.z) and the running sum (params.w): 90% in proportion to an estimate of the light's
// contribution to a scattering point at the volume's centre (phase-averaged: a sun's irradiance
// or a point light's intensity / r^2 over 4 pi, an environment's radiance), 10% uniform, so no
// light with a nonzero estimate is starved. A uniform choice spent half the candidates of the
// bundled smoke on its dim sky; one candidate per light at every vertex cost more than it gave
// (bundled smoke at 128², r2: 4.85x -> 5.26x static, 3.79x -> 3.70x moving with one light by
// power; Blender smoke: 3.53x -> 5.19x and 2.72x -> 3.48x: the sky's light rays through dense
// smoke carry almost nothing).
std::vector<shared::GpuLight> restirLights(const Scene& scene, glm::vec3 centre) {
  std::vector<shared::GpuLight> lights = gpuLights(scene);
  const size_t n = scene.lights.size();
  if (n == 0) return lights;
  auto lum = [](glm::vec3 c) { return std::max(0.0, (double(c.x) + c.y + c.z) / 3.0); };
  std::vector<double> power(n, 0.0);
  double total = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const Light& l = scene.lights[i];
    switch (l.type) {
      case LightType::Sun: power[i] = lum(l.irradiance) / (4.0 * M_PI); break;
      case LightType::Point: {
        const double r2 = std::max(1e-12, double(glm::dot(l.position - centre, l.position - centre)));
        power[i] = lum(l.intensity) / (4.0 * M_PI * r2);
        break;
      }
      case LightType::Environment: power[i] = lum(l.radiance * l.scale); break;
    }
    total += power[i];
  }
  double cdf = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const double p = total > 0.0 ? 0.9 * power[i] / total + 0.1 / double(n) : 1.0 / double(n);
    cdf += p;
    lights[i].params.z = float(p);
    lights[i].params.w = i + 1 == n ? 2.0f : float(cdf);  // the last light catches rounding
  }
  return lights;
}

constexpr uint32_t kSets = 3;  // candidates / temporal / spatial rotate through three sets

}  // namespace

Restir::Restir(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const Scene& scene, const RestirOptions& options)
    : ctx_(ctx), scene_(scene), options_(options), features_(featuresOf(scene)), timer_(ctx, 32) {
  checkGpuSupports(scene, "ReSTIR");
  if (scene.render.maxBounces > int(shared::RS_MAX_VERTICES)) {
    throw InputError(scene.path + strf(": render.max_bounces: ReSTIR stores paths of at most %u vertices (got %d); "
                                       "use mode pt for longer paths",
                                       shared::RS_MAX_VERTICES, scene.render.maxBounces));
  }
  if (options_.neighbours > int(shared::RS_MAX_NEIGHBOURS)) {
    throw InputError(scene.path + strf(": render.restir_neighbours: at most %u", shared::RS_MAX_NEIGHBOURS));
  }
  using gpu::BindingType;
  const BindingType SB = BindingType::StorageBuffer, IMG = BindingType::SampledImage;
  // restir/bindings.glsl: 0..4 volume, 5 frame, 6 lights, 7 params, 8 coarse, 9..12 previous
  // volume, 13 reservoirs, 14 paths, 15 bounces, 16 output, 17 counters.
  const std::vector<BindingType> bindings = {SB, IMG, SB, SB, SB, SB, SB, SB, SB, SB, IMG, SB, SB, SB, SB, SB, SB, SB};
  const gpu::ShaderDefines defines = features_.defines();
  const std::string variant = " [" + features_.name() + "]";
  // Each pass is compiled with only the code its options use (MIS kind, temporal or spatial,
  // light types): on a SIMD back end such as lavapipe the straight-line code of branches not
  // taken still runs under a mask (measured: -20 to -40% per reuse pass).
  auto make = [&](const char* file, const char* name, gpu::ShaderDefines extra) {
    gpu::ShaderDefines d = defines;
    // Final shading estimates f / p̂ per segment by residual ratio tracking against the target's
    // mean field (restir/coarse.glsl) at 16x the residual majorant: on the bundled smoke (64²,
    // temporal reuse) relMSE 0.011 at 1x, 0.0082 at 2x, 0.0054 at 8x, 0.0046 at 16x, 0.0046 at
    // 32x, shading 3.4 -> 5.9 ms; 16x is where the error stops falling (notes/restir.md).
    d.emplace_back("PLUME_RS_RESIDUAL_SCALE", "16.0f");
    d.emplace_back("PLUME_RS_MIS", std::to_string(options_.mis) + "u");
    d.insert(d.end(), extra.begin(), extra.end());
    return std::make_unique<gpu::ComputePass>(ctx, compiler.compile(file, d), bindings,
                                              uint32_t(sizeof(shared::RsPush)), name + variant, glm::uvec3(8, 8, 1));
  };
  candidates_ = make("passes/restir_candidates.comp", "restir candidates", {});
  temporal_ = make("passes/restir_reuse.comp", "restir temporal", {{"PLUME_RS_TEMPORAL", "1"}});
  spatial_ = make("passes/restir_reuse.comp", "restir spatial", {{"PLUME_RS_TEMPORAL", "0"}});
  shade_ = make("passes/restir_shade.comp", "restir shade", {});

  const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  const size_t pixels = size_t(scene.camera.width) * scene.camera.height;
  const uint32_t stride = uint32_t(std::max(1, scene.render.maxBounces - 1));
  frameBuffer_ = gpu::Buffer(ctx, sizeof(shared::GpuFrame), storage, "frame parameters");
  const size_t lightCount = gpuLights(scene).size();
  lightBuffer_ = gpu::Buffer(ctx, lightCount * sizeof(shared::GpuLight), storage, "lights");
  paramBuffer_ = gpu::Buffer(ctx, sizeof(shared::RestirParams), storage, "restir parameters");
  reservoirs_ = gpu::Buffer(ctx, kSets * pixels * sizeof(shared::RsPacked), storage, "reservoirs");
  paths_ = gpu::Buffer(ctx, kSets * pixels * sizeof(shared::RsPathHead), storage, "reservoir paths");
  bounces_ = gpu::Buffer(ctx, kSets * pixels * stride * sizeof(glm::vec4), storage, "reservoir path vertices");
  output_ = gpu::Buffer(ctx, 2 * pixels * sizeof(glm::vec4), storage, "restir accumulation");
  counters_ = gpu::Buffer(ctx, 16, storage, "restir counters");
  counters_.fillZero();
  reservoirs_.fillZero();
  paths_.fillZero();
  for (gpu::ComputePass* p : {candidates_.get(), temporal_.get(), spatial_.get(), shade_.get()}) {
    p->set.bind(5, frameBuffer_);
    p->set.bind(6, lightBuffer_);
    p->set.bind(7, paramBuffer_);
    p->set.bind(13, reservoirs_);
    p->set.bind(14, paths_);
    p->set.bind(15, bounces_);
    p->set.bind(16, output_);
    p->set.bind(17, counters_);
  }
  params_.config = glm::uvec4(uint32_t(options_.candidates), uint32_t(options_.neighbours), 0u, stride);
  params_.configF = glm::vec4(float(options_.radius), float(options_.historyCap), 1.0f, 0.0f);
  params_.frames = glm::uvec4(0u, uint32_t(pixels), 0u, uint32_t(scene.lights.size()));
  params_.misc = glm::uvec4(0u);
}

void Restir::setVolumes(const GpuVolumeResources& current, const GpuVolumeResources& previous) {
  PLUME_CHECK(current.hasMeanField() && previous.hasMeanField());  // baked with BakeOptions::meanField
  for (gpu::ComputePass* p : {candidates_.get(), temporal_.get(), spatial_.get(), shade_.get()}) {
    current.bind(p->set);
    current.bindCoarse(p->set, 8);
    previous.bindAsPrevious(p->set, 9, 10, 11, 12);
  }
  // Reprojection depth: the distance from the camera to the volume's centre (a per-frame
  // constant, so the history pixel never depends on a sample).
  const shared::GpuVolume& v = current.params();
  const glm::vec3 centre = glm::vec3(v.indexToWorld * glm::vec4(0.5f * (glm::vec3(v.boundsMin) + glm::vec3(v.boundsMax)), 1.0f));
  centre_ = centre;
  currentSerial_ = current.serial();
  previousSerial_ = previous.serial();
  std::vector<shared::GpuLight> lights = restirLights(scene_, centre);
  lightBuffer_.upload(lights.data(), lights.size() * sizeof(shared::GpuLight));
}

void Restir::resetHistory() { hasHistory_ = false; }

void Restir::fillFrame(int frame, uint32_t sequence, uint32_t key) {
  frame_ = gpuFrame(scene_, frame, uint32_t(scene_.render.seed) + 0x9E3779B9u * sequence, key, 1u);
  const glm::vec4 c[4] = {frame_.camPosition, frame_.camForward, frame_.camRight, frame_.camUp};
  const bool history = hasHistory_ && options_.historyCap > 0 && prevSequence_ == sequence;
  if (history) {
    params_.prevCamPosition = prevCam_[0];
    params_.prevCamForward = prevCam_[1];
    params_.prevCamRight = prevCam_[2];
    params_.prevCamUp = prevCam_[3];
  }
  params_.frames.z = history ? 1u : 0u;
  // The history's domain is the current one (a still camera over the grid it was rendered with):
  // the temporal shift is the identity and both cross-domain targets are the stored ones.
  bool sameCamera = true;
  for (int i = 0; i < 4; ++i) sameCamera = sameCamera && prevCam_[i] == c[i];
  params_.misc.y = history && sameCamera && previousSerial_ == currentSerial_ && renderedSerial_ == currentSerial_ ? 1u : 0u;
  renderedSerial_ = currentSerial_;
  params_.configF.z = glm::length(centre_ - glm::vec3(c[0]));
  frameBuffer_.upload(&frame_, sizeof(frame_));
  paramBuffer_.upload(&params_, sizeof(params_));
  for (int i = 0; i < 4; ++i) prevCam_[i] = c[i];
}

Image Restir::renderFrame(int frame, uint32_t sequence, uint32_t iteration) {
  render(frame, sequence, iteration, false);
  return readImage();
}

Image Restir::readImage() const { return readAccumulation(output_, scene_.camera.width, scene_.camera.height); }

void Restir::render(int frame, uint32_t sequence, uint32_t iteration, bool accumulate) {
  PLUME_CHECK(iteration < kMaxIterations);
  const uint32_t key = uint32_t(frame) * kMaxIterations + iteration;
  fillFrame(frame, sequence, key);
  const bool temporal = params_.frames.z != 0u;
  const glm::uvec3 items(uint32_t(scene_.camera.width), uint32_t(scene_.camera.height), 1u);
  std::vector<std::string> labels;
  uint32_t finalSet = 0;
  ctx_.submitAndWait([&](VkCommandBuffer cmd) {
    timer_.reset(cmd);
    const uint32_t hist = history_;
    uint32_t cur = (hist + 1) % kSets;
    shared::RsPush push{};
    push.sets = glm::uvec4(0u, 0u, cur, 0u);
    candidates_->record(cmd, items, &push, &timer_);
    labels.push_back("candidates");
    gpu::computeBarrier(cmd);
    if (temporal) {
      const uint32_t out = (hist + 2) % kSets;
      push.sets = glm::uvec4(cur, hist, out, 0u);
      temporal_->record(cmd, items, &push, &timer_);
      labels.push_back("temporal");
      gpu::computeBarrier(cmd);
      cur = out;
    }
    for (int r = 0; r < options_.rounds; ++r) {
      const uint32_t out = (cur + 1) % kSets;
      push.sets = glm::uvec4(cur, cur, out, 0u);
      push.misc = glm::uvec4(uint32_t(r), 0u, 0u, 0u);
      spatial_->record(cmd, items, &push, &timer_);
      labels.push_back(strf("spatial %d", r + 1));
      gpu::computeBarrier(cmd);
      cur = out;
    }
    push.sets = glm::uvec4(cur, cur, cur, 0u);
    push.misc = glm::uvec4(0u, accumulate ? 0u : 1u, 0u, 0u);
    shade_->record(cmd, items, &push, &timer_);
    labels.push_back("shade");
    finalSet = cur;
  });
  passTimes_ = timer_.read();
  for (size_t i = 0; i < passTimes_.size() && i < labels.size(); ++i) passTimes_[i].first = labels[i];
  history_ = finalSet;
  hasHistory_ = true;
  prevSequence_ = sequence;
}

uint32_t Restir::takeDroppedCount() {
  uint32_t counters[4];
  counters_.download(counters, sizeof counters);
  const uint32_t zero[4] = {0, 0, 0, 0};
  counters_.upload(zero, sizeof zero);
  return counters[0];
}

double Restir::lastFrameGpuMs() const {
  double ms = 0;
  for (const auto& [name, t] : passTimes_) ms += t;
  return ms;
}

}  // namespace plume
