#include "render/path_tracer.h"

#include "core/error.h"
#include "core/log.h"

#include <glm/glm.hpp>

#include <cmath>

namespace plume {

gpu::ShaderDefines FeatureSet::defines() const {
  gpu::ShaderDefines d;
  if (sun) d.emplace_back("PLUME_HAS_SUN", "1");
  if (point) d.emplace_back("PLUME_HAS_POINT", "1");
  if (environment) d.emplace_back("PLUME_HAS_ENV", "1");
  if (multiBounce) d.emplace_back("PLUME_MULTI_BOUNCE", "1");
  return d;
}

std::string FeatureSet::name() const {
  std::string n;
  auto add = [&](bool on, const char* s) {
    if (on) n += (n.empty() ? "" : "+") + std::string(s);
  };
  add(sun, "sun");
  add(point, "point");
  add(environment, "env");
  add(multiBounce, "multi");
  return n.empty() ? "none" : n;
}

FeatureSet featuresOf(const Scene& scene) {
  FeatureSet f;
  for (const Light& l : scene.lights) {
    f.sun |= l.type == LightType::Sun;
    f.point |= l.type == LightType::Point;
    f.environment |= l.type == LightType::Environment;
  }
  f.multiBounce = scene.render.maxBounces > 1;
  return f;
}

namespace {

std::vector<shared::GpuLight> gpuLights(const Scene& scene) {
  std::vector<shared::GpuLight> out;
  for (const Light& l : scene.lights) {
    shared::GpuLight g{};
    switch (l.type) {
      case LightType::Sun: {
        g.dirOrPos = glm::vec4(glm::normalize(l.toLight), 0.0f);
        const double alpha = glm::radians(double(l.angularRadiusDeg));
        if (alpha > 0) {
          // A disk of uniform radiance L with irradiance E: E = L * pi * sin^2(alpha).
          g.emission = glm::vec4(glm::dvec3(l.irradiance) / (M_PI * std::sin(alpha) * std::sin(alpha)), 0.0f);
          g.params = glm::vec4(float(shared::LIGHT_SUN), float(std::cos(alpha)), 0.0f, 0.0f);
        } else {
          g.emission = glm::vec4(l.irradiance, 0.0f);
          g.params = glm::vec4(float(shared::LIGHT_SUN), 1.0f, 0.0f, 0.0f);
        }
        break;
      }
      case LightType::Point:
        g.dirOrPos = glm::vec4(l.position, 1.0f);
        g.emission = glm::vec4(l.intensity, 0.0f);
        g.params = glm::vec4(float(shared::LIGHT_POINT), 0.0f, 0.0f, 0.0f);
        break;
      case LightType::Environment:
        g.emission = glm::vec4(l.radiance * l.scale, 0.0f);
        g.params = glm::vec4(float(shared::LIGHT_ENVIRONMENT), 0.0f, 0.0f, 0.0f);
        break;
    }
    out.push_back(g);
  }
  if (out.size() > size_t(shared::GPU_MAX_LIGHTS)) {
    throw InputError(scene.path + strf(": lights: at most %d lights are supported", shared::GPU_MAX_LIGHTS));
  }
  if (out.empty()) out.push_back(shared::GpuLight{});  // keep the buffer non-empty
  return out;
}

}  // namespace

PathTracer::PathTracer(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const Scene& scene)
    : ctx_(ctx), scene_(scene), features_(featuresOf(scene)), compiler_(compiler), timer_(ctx) {
  if (!scene.surfaces.empty()) throw InputError(scene.path + ": surfaces: not supported by the GPU path tracer yet");
  for (size_t i = 0; i < scene.media.size(); ++i) {
    if (scene.media[i].emission) throw InputError(scene.path + strf(": media[%zu].emission: not supported yet", i));
  }
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    if (!scene.lights[i].map.empty()) throw InputError(scene.path + strf(": lights[%zu].map: not supported yet", i));
  }
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
  if (skipEmpty) defines.emplace_back("PLUME_SKIP_EMPTY", "1");
  pass = std::make_unique<gpu::ComputePass>(
      ctx_, compiler_.compile("passes/pt.comp", defines),
      std::vector<BindingType>{BindingType::StorageBuffer, BindingType::SampledImage, BindingType::StorageBuffer,
                               BindingType::StorageBuffer, BindingType::StorageBuffer, BindingType::StorageBuffer,
                               BindingType::StorageBuffer, BindingType::StorageBuffer},
      0, "path tracing [" + features_.name() + (skipEmpty ? "+skip" : "") + "]", glm::uvec3(8, 8, 1));
  pass->set.bind(5, frameBuffer_);
  pass->set.bind(6, lightBuffer_);
  pass->set.bind(7, accum_);
  return *pass;
}

std::string PathTracer::variantName() const { return features_.name() + (skipEmpty_ ? "+skip" : ""); }

void PathTracer::setVolume(const GpuVolumeResources& volume) {
  // Skipping pays when rays cross many bricks: a brick grid wider than 16 on some axis.
  const shared::GpuVolume& p = volume.params();
  const int widest = std::max(p.brickDims.x, std::max(p.brickDims.y, p.brickDims.z));
  skipEmpty_ = p.info.x >= 2u && widest > 16;
  pass_ = &makePass(skipEmpty_);
  volume.bind(pass_->set);
}

void PathTracer::beginFrame(int frame) {
  const Camera& cam = scene_.camera;
  const CameraPose pose = cam.poseAt(frame);
  const glm::vec3 forward = glm::normalize(pose.lookAt - pose.position);
  const glm::vec3 right = glm::normalize(glm::cross(forward, pose.up));
  const glm::vec3 up = glm::cross(right, forward);
  const Medium& m = scene_.media.at(0);
  const RenderSettings& rs = scene_.render;
  frame_.camPosition = glm::vec4(pose.position, float(std::tan(glm::radians(double(pose.fovY)) * 0.5)));
  frame_.camForward = glm::vec4(forward, float(cam.width) / float(cam.height));
  frame_.camRight = glm::vec4(right, 0.0f);
  frame_.camUp = glm::vec4(up, 0.0f);
  frame_.albedo = glm::vec4(m.albedo, m.g);
  frame_.image = glm::uvec4(uint32_t(cam.width), uint32_t(cam.height), 0u, uint32_t(rs.maxBounces));
  frame_.seeds = glm::uvec4(uint32_t(rs.seed), uint32_t(frame), 0u, uint32_t(rs.rrStartBounce));
  frame_.lights = glm::uvec4(uint32_t(scene_.lights.size()), 0u, 0u, 0u);
  accum_.fillZero();
  samples_ = 0;
}

void PathTracer::addSamples(int spp) {
  frame_.image.z = uint32_t(spp);
  frame_.seeds.z = uint32_t(samples_);
  frameBuffer_.upload(&frame_, sizeof(frame_));
  const glm::uvec3 items(uint32_t(scene_.camera.width), uint32_t(scene_.camera.height), 1u);
  ctx_.submitAndWait([&](VkCommandBuffer cmd) {
    timer_.reset(cmd);
    pass_->record(cmd, items, nullptr, &timer_);
  });
  passTimes_ = timer_.read();
  samples_ += spp;
}

Image PathTracer::readImage() const {
  const Camera& cam = scene_.camera;
  const size_t pixels = size_t(cam.width) * cam.height;
  std::vector<glm::vec4> data(2 * pixels);
  accum_.download(data.data(), data.size() * sizeof(glm::vec4));
  Image image(cam.width, cam.height, true);
  for (size_t i = 0; i < pixels; ++i) {
    const glm::vec4 mean = data[2 * i];
    const glm::vec3 m2 = glm::vec3(data[2 * i + 1]);
    const float n = mean.w;
    const glm::vec3 varMean = n > 1 ? glm::max(glm::vec3(0.0f), m2 / (n * (n - 1.0f))) : glm::vec3(0.0f);
    const int x = int(i % size_t(cam.width)), y = int(i / size_t(cam.width));
    image.setPixel(x, y, glm::vec3(mean));
    image.setVariance(x, y, varMean);
  }
  return image;
}

}  // namespace plume
