#include "render/filter_probe.h"

#include "core/log.h"
#include "gpu/context.h"
#include "gpu/pipeline.h"
#include "gpu/resources.h"
#include "gpu/shader_compiler.h"

#include <glm/gtc/packing.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

namespace plume {

namespace {

constexpr uint32_t kProbePoints = 4096;

// The worst error over the probe's points for one image format, in units of the spread (7).
double probeFormat(gpu::Context& ctx, const std::vector<uint32_t>& spirv, VkFormat format) {
  const bool half = format == VK_FORMAT_R16_SFLOAT;
  gpu::Image3D image(ctx, glm::ivec3(2), format, half ? 2 : 4, "filter probe image");
  if (!image.linearFilter()) return std::numeric_limits<double>::infinity();
  std::vector<float> values(8);
  for (int i = 0; i < 8; ++i) values[size_t(i)] = float((i & 1) + 2 * ((i >> 1) & 1) + 4 * ((i >> 2) & 1));
  if (half) {
    std::vector<uint16_t> h(8);
    for (int i = 0; i < 8; ++i) h[size_t(i)] = glm::packHalf1x16(values[size_t(i)]);
    image.upload(h.data(), h.size() * sizeof(uint16_t));
  } else {
    image.upload(values.data(), values.size() * sizeof(float));
  }
  gpu::Buffer out(ctx, kProbePoints * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "filter probe results");
  gpu::ComputePass pass(ctx, spirv,
                        {gpu::BindingType::SampledImage, gpu::BindingType::StorageBuffer}, 0, "filter probe",
                        glm::uvec3(64, 1, 1));
  pass.set.bind(0, image);
  pass.set.bind(1, out);
  ctx.submitAndWait([&](VkCommandBuffer cmd) { pass.record(cmd, glm::uvec3(kProbePoints, 1, 1)); });
  std::vector<float> err(kProbePoints);
  out.download(err.data(), err.size() * sizeof(float));
  double worst = 0.0;
  for (float e : err) worst = std::isfinite(e) ? std::max(worst, double(e)) : std::numeric_limits<double>::infinity();
  return worst / 7.0;
}

}  // namespace

double filterWeightError(gpu::Context& ctx, gpu::ShaderCompiler& compiler) {
  if (std::optional<double> known = ctx.filterWeightError()) return *known;
  const std::vector<uint32_t> spirv = compiler.compile("passes/filter_probe.comp", {});
  const double e = std::max(probeFormat(ctx, spirv, VK_FORMAT_R16_SFLOAT), probeFormat(ctx, spirv, VK_FORMAT_R32_SFLOAT));
  ctx.setFilterWeightError(e);
  logInfo(strf("%s: the texture unit's trilinear weights are exact to %.3g of the texels' spread (%s)",
                ctx.deviceName().c_str(), e, e <= kExactFilterTolerance ? "density_filter auto reads through it"
                                                                         : "density_filter auto reads 8 texels"));
  return e;
}

bool useHardwareFilter(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const std::string& setting) {
  if (setting == "biased-hardware") return true;
  if (setting == "auto") return filterWeightError(ctx, compiler) <= kExactFilterTolerance;
  return false;
}

}  // namespace plume
