#include "render/gpu_envmap.h"

#include "core/error.h"
#include "core/log.h"
#include "shaders/shared/bindings.h"
#include "shaders/shared/envmap.h"

#include <glm/glm.hpp>

#include <cmath>
#include <cstring>
#include <vector>

namespace plume {

glm::dmat3 envMapWorldToLocal(glm::vec3 upIn, float rotateYDeg) {
  const glm::dvec3 up = glm::normalize(glm::dvec3(upIn));
  const glm::dvec3 y(0, 1, 0);
  glm::dmat3 M(1.0);
  const double c = glm::dot(up, y);
  if (1.0 + c < 1e-12) {
    M = glm::dmat3(1, 0, 0, 0, -1, 0, 0, 0, -1);  // 180 degrees about X (columns)
  } else {
    // Rodrigues for the rotation taking up to y: I + [v]x + [v]x^2 / (1 + c), v = up x y.
    const glm::dvec3 v = glm::cross(up, y);
    const glm::dmat3 K(0, v.z, -v.y, -v.z, 0, v.x, v.y, -v.x, 0);  // columns of [v]x
    M = glm::dmat3(1.0) + K + K * K * (1.0 / (1.0 + c));
  }
  // R_y(a), right-handed: x' = cos a x + sin a z, z' = -sin a x + cos a z; a = -theta.
  const double a = -glm::radians(double(rotateYDeg));
  const glm::dmat3 Ry(std::cos(a), 0, -std::sin(a), 0, 1, 0, std::sin(a), 0, std::cos(a));
  return Ry * M;
}

EnvMapData buildEnvMapData(const EnvironmentMapImage& image, float scale, glm::vec3 up, float rotateYDeg) {
  const uint32_t W = uint32_t(image.width), H = uint32_t(image.height);
  EnvMapData out;
  const glm::dmat3 R = envMapWorldToLocal(up, rotateYDeg);
  const glm::dmat3 rows = glm::transpose(R);  // column k of the transpose = row k of R
  out.header.toLocal0 = glm::vec4(glm::vec3(rows[0]), 0.0f);
  out.header.toLocal1 = glm::vec4(glm::vec3(rows[1]), 0.0f);
  out.header.toLocal2 = glm::vec4(glm::vec3(rows[2]), 0.0f);
  out.header.width = W;
  out.header.height = H;
  out.data.assign(shared::env_data_size(W, H), 0.0f);
  float* texels = out.data.data();
  float* marginal = texels + shared::env_marginal_offset(out.header);
  std::vector<double> rowSum(H, 0.0), f(W);
  glm::dvec3 mean(0.0);
  for (uint32_t r = 0; r < H; ++r) {
    // f = luminance * sin(theta) at the row's centre; the solid angle of the row's texels is
    // proportional to (cos theta0 - cos theta1), used for the mean radiance.
    const double sinTheta = std::sin(M_PI * (r + 0.5) / H);
    const double rowSolidAngle = (std::cos(M_PI * r / H) - std::cos(M_PI * (r + 1.0) / H)) * 2.0 * M_PI / W;
    float* cdf = out.data.data() + shared::env_conditional_offset(out.header, r);
    for (uint32_t c = 0; c < W; ++c) {
      const glm::vec3 L = image.texels[size_t(r) * W + c] * scale;
      for (int k = 0; k < 3; ++k) texels[3 * (size_t(r) * W + c) + k] = L[k];
      f[c] = double(shared::env_luminance(L)) * sinTheta;
      rowSum[r] += f[c];
      mean += glm::dvec3(L) * rowSolidAngle;
    }
    // The conditional CDF (uniform for a black row, which the marginal never picks).
    double acc = 0.0;
    cdf[0] = 0.0f;
    for (uint32_t c = 0; c < W; ++c) {
      acc += rowSum[r] > 0.0 ? f[c] : 1.0;
      cdf[c + 1] = float(acc / (rowSum[r] > 0.0 ? rowSum[r] : double(W)));
    }
    cdf[W] = 1.0f;
  }
  double total = 0.0;
  for (double s : rowSum) total += s;
  double acc = 0.0;
  marginal[0] = 0.0f;
  for (uint32_t r = 0; r < H; ++r) {
    // An all-black map is drawn uniformly in (u, v): its radiance is 0 wherever it samples.
    acc += total > 0.0 ? rowSum[r] : 1.0;
    marginal[r + 1] = float(acc / (total > 0.0 ? total : double(H)));
  }
  marginal[H] = 1.0f;
  out.meanRadiance = glm::vec3(mean / (4.0 * M_PI));
  return out;
}

EnvironmentMapLimit envMapLimit(const VkPhysicalDeviceLimits& limits) {
  EnvironmentMapLimit l;
  // One texel buffer of 32-bit words: the header, then the data (scene/bindings.glsl).
  const uint64_t words = limits.maxTexelBufferElements;
  const uint64_t header = sizeof(shared::GpuEnvMap) / 4;
  l.maxTexels = words > header ? (words - header) / (kEnvMapBytesPerTexel / 4) : 0;
  l.what = strf("the device's maxTexelBufferElements (%llu words, at %llu words per texel)", (unsigned long long)words,
                (unsigned long long)(kEnvMapBytesPerTexel / 4));
  return l;
}

GpuEnvironmentMap::GpuEnvironmentMap(gpu::Context& ctx, const Scene& scene) {
  EnvMapData d;
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& l = scene.lights[i];
    if (l.map.empty()) continue;
    const EnvironmentMapImage image =
        loadEnvironmentMap(l.map, scene.path + strf(": lights[%zu].map", i), envMapLimit(ctx.limits()));
    d = buildEnvMapData(image, l.scale, l.up, l.rotateYDeg);
    present_ = true;
    meanRadiance_ = d.meanRadiance;
  }
  if (!present_) {
    EnvironmentMapImage black;
    black.width = 2;
    black.height = 1;
    black.texels.assign(2, glm::vec3(0.0f));
    d = buildEnvMapData(black, 1.0f, glm::vec3(0, 1, 0), 0.0f);
  }
  static_assert(sizeof(shared::GpuEnvMap) == 64, "scene/bindings.glsl reads 16 header words");
  std::vector<uint32_t> words(sizeof(d.header) / 4 + d.data.size());
  std::memcpy(words.data(), &d.header, sizeof(d.header));
  std::memcpy(words.data() + sizeof(d.header) / 4, d.data.data(), d.data.size() * sizeof(float));
  buffer_ = gpu::TexelBuffer(ctx, words.data(), words.size(), VK_FORMAT_R32_UINT, "environment map");
}

void GpuEnvironmentMap::bind(gpu::DescriptorSet& set) const { set.bind(shared::BIND_ENV_MAP, buffer_); }

}  // namespace plume
