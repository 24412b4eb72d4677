#include "render/gpu_scene.h"

#include "core/error.h"
#include "core/log.h"
#include "render/gpu_surfaces.h"
#include "render/gpu_volume.h"
#include "shaders/shared/bindings.h"

#include <glm/glm.hpp>

#include <cmath>

namespace plume {

std::vector<shared::GpuLight> gpuLights(const Scene& scene) {
  std::vector<shared::GpuLight> out;
  for (const Light& l : scene.lights) {
    shared::GpuLight g{};
    switch (l.type) {
      case LightType::Sun: {
        g.type = shared::LIGHT_SUN;
        g.dirOrPos = glm::normalize(l.toLight);
        const double alpha = glm::radians(double(l.angularRadiusDeg));
        if (alpha > 0) {
          // A disk of uniform radiance L with irradiance E: E = L * pi * sin^2(alpha).
          g.emission = glm::vec3(glm::dvec3(l.irradiance) / (M_PI * std::sin(alpha) * std::sin(alpha)));
          g.versine = float(2.0 * std::sin(0.5 * alpha) * std::sin(0.5 * alpha));  // 1 - cos(alpha)
        } else {
          g.emission = l.irradiance;
          g.versine = 0.0f;
        }
        break;
      }
      case LightType::Point:
        g.type = shared::LIGHT_POINT;
        g.dirOrPos = l.position;
        g.emission = l.intensity;
        break;
      case LightType::Environment:
        g.type = l.map.empty() ? shared::LIGHT_ENVIRONMENT : shared::LIGHT_ENV_MAP;
        g.emission = l.map.empty() ? l.radiance * l.scale : glm::vec3(0.0f);  // a map's texels hold L * scale
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

gpu::TexelBuffer lightTexels(gpu::Context& ctx, const std::vector<shared::GpuLight>& lights) {
  static_assert(sizeof(shared::GpuLight) == 32, "two uvec4 texels per light");
  PLUME_CHECK(!lights.empty());
  return gpu::TexelBuffer(ctx, lights.data(), lights.size() * 2, VK_FORMAT_R32G32B32A32_UINT, "lights");
}

shared::GpuCamera gpuCamera(const Camera& cam, int frame) {
  const CameraPose pose = cam.poseAt(frame);
  shared::GpuCamera c{};
  c.position = pose.position;
  c.tanHalfFovY = float(std::tan(glm::radians(double(pose.fovY)) * 0.5));
  c.forward = glm::normalize(pose.lookAt - pose.position);
  c.aspect = float(cam.width) / float(cam.height);
  c.right = glm::normalize(glm::cross(c.forward, pose.up));
  c.up = glm::cross(c.right, c.forward);
  return c;
}

bool sameCamera(const shared::GpuCamera& a, const shared::GpuCamera& b) {
  return a.position == b.position && a.tanHalfFovY == b.tanHalfFovY && a.forward == b.forward &&
         a.aspect == b.aspect && a.right == b.right && a.up == b.up;
}

shared::GpuFrame gpuFrame(const Scene& scene, int frame, uint32_t seed, uint32_t frameKey) {
  const Camera& cam = scene.camera;
  const Medium& m = scene.medium();
  const RenderSettings& rs = scene.render;
  shared::GpuFrame f{};
  f.camera = gpuCamera(cam, frame);
  f.albedo = m.albedo;
  f.g = m.g;
  f.size = glm::uvec2(uint32_t(cam.width), uint32_t(cam.height));
  f.maxBounces = uint32_t(rs.maxBounces);
  f.seed = seed;
  f.frameKey = frameKey;
  f.firstSample = 0u;
  f.rrStartBounce = uint32_t(rs.rrStartBounce);
  f.lightCount = uint32_t(scene.lights.size());
  f.loopProbe = 2u;  // volume/loop_guard.glsl
  return f;
}

namespace {

// The image (mean and variance of the mean) of accumulation data, 2 vec4 per pixel.
Image accumulationImage(const std::vector<glm::vec4>& data, int width, int height) {
  const size_t pixels = size_t(width) * height;
  Image image(width, height, true);
  for (size_t i = 0; i < pixels; ++i) {
    const glm::vec4 mean = data[2 * i];
    const glm::vec3 m2 = glm::vec3(data[2 * i + 1]);
    const float n = mean.w;
    const glm::vec3 varMean = n > 1 ? glm::max(glm::vec3(0.0f), m2 / (n * (n - 1.0f))) : glm::vec3(0.0f);
    const int x = int(i % size_t(width)), y = int(i / size_t(width));
    image.setPixel(x, y, glm::vec3(mean));
    image.setVariance(x, y, varMean);
  }
  return image;
}

}  // namespace

Image readAccumulation(const std::vector<gpu::Buffer>& bands, uint32_t bandPixels, int width, int height) {
  const size_t pixels = size_t(width) * height;
  std::vector<glm::vec4> data(2 * pixels);
  for (size_t b = 0; b < bands.size(); ++b) {
    const size_t begin = b * bandPixels, n = std::min<size_t>(bandPixels, pixels - begin);
    bands[b].download(data.data() + 2 * begin, n * 2 * sizeof(glm::vec4));
  }
  return accumulationImage(data, width, height);
}

Image readAccumulation(const gpu::Buffer& accum, int width, int height) {
  std::vector<glm::vec4> data(2 * size_t(width) * height);
  accum.download(data.data(), data.size() * sizeof(glm::vec4));
  return accumulationImage(data, width, height);
}

gpu::BindingTypes sceneBindingTypes(bool restir, bool emission, bool surfaces, uint32_t surfaceShift) {
  gpu::BindingTypes t = GpuVolumeResources::bindingTypes(restir, emission);
  t.push_back({shared::BIND_LIGHTS, gpu::BindingType::TexelBuffer});
  t.push_back({shared::BIND_ENV_MAP, gpu::BindingType::TexelBuffer});
  if (surfaces) {
    const gpu::BindingTypes s = GpuSurfaces::bindingTypes(surfaceShift);
    t.insert(t.end(), s.begin(), s.end());
  }
  return t;
}

}  // namespace plume
