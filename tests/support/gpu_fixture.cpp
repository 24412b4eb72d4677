#include "support/gpu_fixture.h"

#include "media/vdb_loader.h"
#include "reference/reference.h"
#include "render/gpu_volume.h"
#include "render/path_tracer.h"
#include "support/reference_check.h"

namespace plume::test {

std::unique_ptr<gpu::Context> GpuTest::ctx_;
std::unique_ptr<gpu::ShaderCompiler> GpuTest::compiler_;

void GpuTest::SetUpTestSuite() {
  if (!ctx_) {
    gpu::ContextOptions options;
    options.validation = true;
    options.verbose = true;
    ctx_ = std::make_unique<gpu::Context>(options);
    compiler_ = std::make_unique<gpu::ShaderCompiler>();
  }
}

void GpuTest::TearDownTestSuite() {}

// Destroys the shared context when the tests are done, before main returns. Left to the static
// destructors, it would be destroyed after those of the validation layer (loaded later, so torn
// down first) and lavapipe's instance would never be freed (LeakSanitizer, tools/test --sanitize).
class GpuEnvironment : public ::testing::Environment {
 public:
  void TearDown() override {
    GpuTest::compiler_.reset();
    GpuTest::ctx_.reset();
  }
};
namespace {
[[maybe_unused]] const auto* const kGpuEnvironment = ::testing::AddGlobalTestEnvironment(new GpuEnvironment);
}  // namespace

void GpuTest::SetUp() { messagesBefore_ = ctx_->validationMessages(); }

void GpuTest::TearDown() {
  EXPECT_EQ(ctx_->validationMessages(), messagesBefore_) << "Vulkan validation reported problems (see stderr)";
}

Image renderGpuPt(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const Scene& scene,
                  openvdb::FloatGrid::Ptr grid, int frame, GpuRenderInfo* info, TexelFormat format,
                  openvdb::FloatGrid::Ptr emission) {
  LoadedGrid loaded;
  loaded.grid = grid;
  loaded.name = "density";
  BakeOptions options;
  options.format = format;
  BakedVolume bake = bakeVolume(loaded, options);
  if (emission) {
    LoadedGrid e;
    e.grid = emission;
    e.name = "emission";
    bakeEmission(bake, loaded, e);
  }
  const auto& em = scene.medium().emission;
  GpuVolumeResources volume(ctx, bake, scene.medium().densityScale, emission && em ? &*em : nullptr);
  PathTracer tracer(ctx, compiler, scene);
  tracer.setVolume(volume);
  tracer.beginFrame(frame);
  for (int done = 0; done < scene.render.spp; done += 16) tracer.addSamples(std::min(16, scene.render.spp - done));
  if (info) {
    info->variant = tracer.variantName();
    info->truncated = volume.truncatedCount() + volume.loopLimitCount();  // both are truncations
  }
  return tracer.readImage();
}

ReferenceCheck expectPtMatchesReference(gpu::Context& ctx, gpu::ShaderCompiler& compiler, Scene s,
                                        openvdb::FloatGrid::Ptr grid, int gpuSpp, int refSpp, const std::string& name,
                                        const std::string& outputGroup, const std::string& feature,
                                        float mustFailScale) {
  Scene refScene = s;
  refScene.render.spp = refSpp;
  refScene.render.seed = 4242;
  ref::ReferenceOptions opt;
  opt.progress = false;
  const Image ref = ref::renderReference(refScene, grid, opt);
  s.render.spp = gpuSpp;
  GpuRenderInfo info;
  const Image gpu = renderGpuPt(ctx, compiler, s, grid, 1, &info);
  EXPECT_NE(info.variant.find(feature), std::string::npos) << info.variant;
  ReferenceCheckOptions options;
  options.outputGroup = outputGroup;
  const ReferenceCheck check = expectMatchesReference(gpu, ref, name, options);
  EXPECT_EQ(info.truncated, 0u) << name;
  if (mustFailScale > 0.0f) {
    Image scaled = gpu;
    for (float& v : scaled.rgb) v *= mustFailScale;
    for (float& v : scaled.var) v *= mustFailScale * mustFailScale;
    EXPECT_FALSE(checkAgainstReference(scaled, ref, options).pass()) << name << ": the image times " << mustFailScale << " passes too";
  }
  return check;
}

}  // namespace plume::test
