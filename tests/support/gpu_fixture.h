// GPU test helpers: one Vulkan context per test program with validation layers on (every
// validation message fails the test that caused it), the shader compiler without a disk cache,
// and a one-call GPU path-traced render.
#pragma once

#include "gpu/context.h"
#include "gpu/shader_compiler.h"
#include "io/image.h"
#include "media/bake.h"
#include "scene/scene.h"
#include "support/reference_check.h"

#include <gtest/gtest.h>
#include <openvdb/openvdb.h>

#include <memory>

namespace plume::test {

class GpuTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite();
  static void TearDownTestSuite();
  void SetUp() override;
  void TearDown() override;  // fails the test on new validation messages

  static gpu::Context& ctx() { return *ctx_; }
  static gpu::ShaderCompiler& compiler() { return *compiler_; }

 private:
  friend class GpuEnvironment;
  static std::unique_ptr<gpu::Context> ctx_;
  static std::unique_ptr<gpu::ShaderCompiler> compiler_;
  uint64_t messagesBefore_ = 0;
};

struct GpuRenderInfo {
  std::string variant;
  uint32_t truncated = 0;
};

// Bakes `grid`, renders scene.render.spp samples per pixel of `frame` with the GPU path tracer.
// `emission`: the medium's emission grid (scene.medium().emission must be set with it).
Image renderGpuPt(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const Scene& scene,
                  openvdb::FloatGrid::Ptr grid, int frame = 1, GpuRenderInfo* info = nullptr,
                  TexelFormat format = TexelFormat::Float16, openvdb::FloatGrid::Ptr emission = nullptr);

// Renders `scene` with the GPU path tracer at gpuSpp and with the CPU reference at refSpp (seed
// 4242) and expects them to agree (support/reference_check.h: per-pixel and aggregate z-tests,
// outputs under `outputGroup`), with no truncation, in a shader variant whose name contains
// `feature`. `mustFailScale` > 0: the same check with the path tracer's image (and its variance)
// scaled by it must fail, so the test is shown able to see such a bias. Returns the check.
ReferenceCheck expectPtMatchesReference(gpu::Context& ctx, gpu::ShaderCompiler& compiler, Scene scene,
                                        openvdb::FloatGrid::Ptr grid, int gpuSpp, int refSpp, const std::string& name,
                                        const std::string& outputGroup, const std::string& feature,
                                        float mustFailScale = 0.0f);

}  // namespace plume::test
