// render.density_filter: whether the GPU estimators read the density and emission grids through
// the texture unit's trilinear filter (one texture() call, PLUME_HW_FILTER) or with 8 texel reads
// and exact weights. The filter's weights are the device's: rounded to 8 bits on most GPUs
// (VkPhysicalDeviceLimits::subTexelPrecisionBits), float on lavapipe. `auto` (the default) uses
// the filter only where it is measured to be exact: its weights' error at most
// kExactFilterTolerance of the 8 texels' spread, 2^-16, 256 times finer than 8-bit weights (whose
// bias the 8-bit emulation could not resolve either: notes/bench/hardware_filter.md).
#pragma once

#include <string>

namespace plume {

namespace gpu {
class Context;
class ShaderCompiler;
}  // namespace gpu

constexpr double kExactFilterTolerance = 1.0 / 65536.0;

// The worst error of the texture unit's trilinear weights on this device, as a fraction of the 8
// texels' spread: 4096 points in 2x2x2 images of each format the grids use (R16F, R32F),
// shaders/passes/filter_probe.comp; infinity where a format cannot be filtered linearly.
// Measured once per context (a compile and a dispatch) and kept in it.
double filterWeightError(gpu::Context& ctx, gpu::ShaderCompiler& compiler);

// Whether `setting` (render.density_filter) reads the grids through the texture unit on this
// device: "biased-hardware" always, "auto" where filterWeightError <= kExactFilterTolerance,
// "exact" never.
bool useHardwareFilter(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const std::string& setting);

}  // namespace plume
