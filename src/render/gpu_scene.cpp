#include "render/gpu_scene.h"

#include "core/error.h"
#include "core/log.h"

#include <glm/glm.hpp>

#include <cmath>

namespace plume {

void checkGpuSupports(const Scene& scene, const std::string& renderer) {
  if (!scene.surfaces.empty()) throw InputError(scene.path + ": surfaces: not supported by " + renderer + " yet");
  for (size_t i = 0; i < scene.media.size(); ++i) {
    if (scene.media[i].emission) throw InputError(scene.path + strf(": media[%zu].emission: not supported yet", i));
  }
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    if (!scene.lights[i].map.empty()) throw InputError(scene.path + strf(": lights[%zu].map: not supported yet", i));
  }
}

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
          const double versine = 2.0 * std::sin(0.5 * alpha) * std::sin(0.5 * alpha);  // 1 - cos(alpha)
          g.params = glm::vec4(float(shared::LIGHT_SUN), float(versine), 0.0f, 0.0f);
        } else {
          g.emission = glm::vec4(l.irradiance, 0.0f);
          g.params = glm::vec4(float(shared::LIGHT_SUN), 0.0f, 0.0f, 0.0f);
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

void gpuCameraVectors(const Camera& cam, int frame, glm::vec4 out[4]) {
  const CameraPose pose = cam.poseAt(frame);
  const glm::vec3 forward = glm::normalize(pose.lookAt - pose.position);
  const glm::vec3 right = glm::normalize(glm::cross(forward, pose.up));
  const glm::vec3 up = glm::cross(right, forward);
  out[0] = glm::vec4(pose.position, float(std::tan(glm::radians(double(pose.fovY)) * 0.5)));
  out[1] = glm::vec4(forward, float(cam.width) / float(cam.height));
  out[2] = glm::vec4(right, 0.0f);
  out[3] = glm::vec4(up, 0.0f);
}

shared::GpuFrame gpuFrame(const Scene& scene, int frame, uint32_t seed, uint32_t frameKey, uint32_t sppPerDispatch) {
  const Camera& cam = scene.camera;
  const Medium& m = scene.media.at(0);
  const RenderSettings& rs = scene.render;
  glm::vec4 c[4];
  gpuCameraVectors(cam, frame, c);
  shared::GpuFrame f{};
  f.camPosition = c[0];
  f.camForward = c[1];
  f.camRight = c[2];
  f.camUp = c[3];
  f.albedo = glm::vec4(m.albedo, m.g);
  f.image = glm::uvec4(uint32_t(cam.width), uint32_t(cam.height), sppPerDispatch, uint32_t(rs.maxBounces));
  f.seeds = glm::uvec4(seed, frameKey, 0u, uint32_t(rs.rrStartBounce));
  f.lights = glm::uvec4(uint32_t(scene.lights.size()), 0u, 0u, 0u);
  return f;
}

Image readAccumulation(const gpu::Buffer& accum, int width, int height) {
  const size_t pixels = size_t(width) * height;
  std::vector<glm::vec4> data(2 * pixels);
  accum.download(data.data(), data.size() * sizeof(glm::vec4));
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

}  // namespace plume
