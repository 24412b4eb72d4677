// Tier d (DESIGN §7): the GPU path tracer against the independent CPU reference, per-pixel
// Z-test with a Šidák correction and an aggregate z-test on the image mean
// (support/reference_check.h), on small scenes: thin smoke, a dense cloud, multiple
// scattering with albedo 0.99, the camera inside the medium; and two scenes with different
// feature sets compile different shader variants, both correct. Validation layers are on.
#include "core/error.h"
#include "reference/reference.h"
#include "media/vdb_loader.h"
#include "render/filter_probe.h"
#include "render/gpu_volume.h"
#include "render/path_tracer.h"
#include "support/gpu_fixture.h"
#include "support/grids.h"
#include "support/reference_check.h"
#include "support/scenes.h"
#include "support/test_support.h"

#include <glm/glm.hpp>

#include <algorithm>

using namespace plume;

namespace {

class GpuPathTracer : public test::GpuTest {};

Scene baseScene(glm::vec3 position, glm::vec3 lookAt, int size) {
  Scene s;
  s.path = "test-scene";
  s.camera.base.position = position;
  s.camera.base.lookAt = lookAt;
  s.camera.base.fovY = 40.0f;
  s.camera.width = s.camera.height = size;
  s.media.push_back(Medium{});
  s.lights = {test::sunLight({0.4f, 1.0f, 0.3f}, {3.0f, 2.8f, 2.5f}), test::skyLight({0.10f, 0.12f, 0.16f})};
  return s;
}

Scene denseCloudScene() {
  Scene s = baseScene({1.0f, 1.4f, 3.5f}, {1.0f, 1.0f, 1.0f}, 24);
  s.media[0].densityScale = 60.0f;
  s.media[0].albedo = glm::vec3(0.9f);
  s.media[0].g = 0.6f;
  s.render.maxBounces = 6;
  return s;
}

Image renderReference(Scene s, openvdb::FloatGrid::Ptr grid, int spp) {
  s.render.spp = spp;
  s.render.seed = 12345;
  ref::ReferenceOptions opt;
  opt.progress = false;
  return ref::renderReference(s, grid, opt);
}

// Renders on the GPU and with the reference; both must agree (per-pixel and aggregate z-tests).
Image renderAndCompare(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const Scene& scene,
                      openvdb::FloatGrid::Ptr grid, int gpuSpp, int refSpp, const std::string& name,
                      std::string* variant = nullptr) {
  Scene s = scene;
  s.render.spp = gpuSpp;
  test::GpuRenderInfo info;
  Image gpuImage = test::renderGpuPt(ctx, compiler, s, grid, 1, &info);
  Image refImage = renderReference(scene, grid, refSpp);
  test::ReferenceCheckOptions options;
  options.outputGroup = "gpu_pt";
  test::expectMatchesReference(gpuImage, refImage, name, options);
  EXPECT_EQ(info.truncated, 0u) << name;
  if (variant) *variant = info.variant;
  return gpuImage;
}

// Pixels whose value differs from the background (the camera ray hit the medium).
int pixelsShowingMedium(const Image& img, glm::vec3 background) {
  int n = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) n += glm::any(glm::greaterThan(glm::abs(img.pixel(x, y) - background), glm::vec3(1e-4f)));
  return n;
}

}  // namespace

TEST_F(GpuPathTracer, ThinSmokeMatchesReference) {
  Scene s = baseScene({1.0f, 1.2f, 4.0f}, {1.0f, 1.0f, 1.0f}, 24);
  s.media[0].densityScale = 3.0f;
  s.media[0].albedo = glm::vec3(0.8f, 0.85f, 0.9f);
  s.media[0].g = 0.4f;
  s.render.maxBounces = 4;
  renderAndCompare(ctx(), compiler(), s, test::makeNoiseGrid(48, 1.0 / 24), 256, 512, "thin");
}

TEST_F(GpuPathTracer, DenseCloudMatchesReference) {
  Scene s = denseCloudScene();
  renderAndCompare(ctx(), compiler(), s, test::makeNoiseGrid(40, 1.0 / 20, 3), 128, 256, "dense");
}

TEST_F(GpuPathTracer, MultipleScatteringHighAlbedoMatchesReference) {
  Scene s = baseScene({1.0f, 1.0f, 4.0f}, {1.0f, 1.0f, 1.0f}, 20);
  s.media[0].densityScale = 8.0f;
  s.media[0].albedo = glm::vec3(0.99f);
  s.media[0].g = -0.3f;
  s.render.maxBounces = 64;
  renderAndCompare(ctx(), compiler(), s, test::makeNoiseGrid(40, 1.0 / 20, 5), 256, 512, "albedo099");
}

// render.density_filter = biased-hardware (the texture unit's trilinear filter): biased by the
// device's rounding of the weights, which must stay below what this Z-test resolves (README "The
// scene file"); a wrong filter coordinate (half a texel off, a wrong atlas size) fails it.
TEST_F(GpuPathTracer, HardwareFilteredDensityMatchesReference) {
  Scene s = denseCloudScene();
  s.render.densityFilter = "biased-hardware";
  std::string variant;
  renderAndCompare(ctx(), compiler(), s, test::makeNoiseGrid(40, 1.0 / 20, 3), 128, 256, "hwfilter", &variant);
  EXPECT_NE(variant.find("hwfilter"), std::string::npos) << variant;
}

// render.density_filter = exact, the 8 texel reads with exact weights: the default (auto) reads
// through the texture unit wherever its filter is measured exact (render/filter_probe.h: lavapipe),
// so every other Z-test on such a device runs the filter; this one keeps the 8 reads tested there.
TEST_F(GpuPathTracer, ExactLookupsMatchReference) {
  Scene s = denseCloudScene();
  s.render.densityFilter = "exact";
  std::string variant;
  renderAndCompare(ctx(), compiler(), s, test::makeNoiseGrid(40, 1.0 / 20, 3), 128, 256, "exact_lookups", &variant);
  EXPECT_EQ(variant.find("hwfilter"), std::string::npos) << variant;
}

TEST_F(GpuPathTracer, CameraInsideTheMediumMatchesReference) {
  // The camera sits in the box's constant interior, looking across it. The point light in the
  // medium makes both estimators' variance infinite: next-event estimation weighs a vertex at
  // distance r by 1/r², and vertices fall within r with probability ~r³, so P(X > x) ~ x^-1.5.
  // The standard error then shrinks like n^(-1/3), and the variance channels underestimate it:
  // the aggregate test resolves only a ~5% bias here (2.4% with 8 times the samples).
  Scene s = baseScene({1.0f, 1.0f, 1.0f}, {0.2f, 0.8f, 0.3f}, 20);
  s.camera.base.fovY = 70.0f;
  s.media[0].densityScale = 1.5f;
  s.media[0].albedo = glm::vec3(0.7f);
  s.media[0].g = 0.0f;
  s.render.maxBounces = 3;
  Light point;
  point.type = LightType::Point;
  point.position = {1.3f, 1.2f, 0.8f};
  point.intensity = {1.0f, 1.0f, 1.0f};
  s.lights.push_back(point);
  renderAndCompare(ctx(), compiler(), s, test::makeBoxGrid(32, 1.0 / 16), 128, 256, "inside");
}

TEST_F(GpuPathTracer, FeatureSetsCompileDifferentVariantsAndBothMatch) {
  auto grid = test::makeNoiseGrid(32, 1.0 / 16, 7);
  Scene single = baseScene({1.0f, 1.2f, 4.0f}, {1.0f, 1.0f, 1.0f}, 16);
  single.lights.resize(1);  // sun only
  single.media[0].densityScale = 4.0f;
  single.media[0].albedo = glm::vec3(0.9f);
  single.render.maxBounces = 1;
  Scene multi = single;
  multi.lights = baseScene({}, {0, 0, 1}, 1).lights;  // sun + environment
  multi.render.maxBounces = 8;
  // render.density_filter auto reads through the texture unit where the device's filter is
  // measured exact (render/filter_probe.h; measured here first, so its compile is not counted).
  const std::string filter = useHardwareFilter(ctx(), compiler(), "auto") ? "+hwfilter" : "";
  const uint64_t compilesBefore = compiler().compiles();
  std::string v1, v2;
  // 512 and 1024 samples: the sun-only image is noisier than its size suggests (a single bounce
  // with no sky); with 256 and 512 its aggregate test resolves only a 2.7% bias.
  renderAndCompare(ctx(), compiler(), single, grid, 512, 1024, "variant_single", &v1);
  renderAndCompare(ctx(), compiler(), multi, grid, 512, 1024, "variant_multi", &v2);
  EXPECT_EQ(v1, "sun" + filter);
  EXPECT_EQ(v2, "sun+env+multi" + filter);
  // Each path tracer compiles its six kernels: camera rays, extension, shading and the background
  // (the pixels whose rays all miss) for its feature set, and the feature-independent queue and
  // resolve kernels.
  EXPECT_EQ(compiler().compiles() - compilesBefore, 12u);
  EXPECT_NE(featuresOf(single).defines(), featuresOf(multi).defines());
}

TEST_F(GpuPathTracer, SparseVolumeSkipsEmptySpaceCorrectly) {
  // Two noise blobs 180 voxels apart along x: the walk crosses empty level-1 cells between them.
  auto grid = test::makeNoiseGrid(20, 1.0 / 40, 9);
  auto far = test::makeNoiseGrid(20, 1.0 / 40, 11);
  far->transform().postTranslate(openvdb::Vec3d(0));  // same transform; move the voxels instead
  auto acc = grid->getAccessor();
  for (auto it = far->cbeginValueOn(); it; ++it) acc.setValue(it.getCoord() + openvdb::Coord(180, 6, 0), *it);
  Scene s = baseScene({-1.5f, 0.4f, 0.25f}, {3.0f, 0.3f, 0.25f}, 20);
  s.camera.base.fovY = 25.0f;
  s.media[0].densityScale = 12.0f;
  s.media[0].albedo = glm::vec3(0.85f);
  s.render.maxBounces = 4;
  std::string variant;
  Image img = renderAndCompare(ctx(), compiler(), s, grid, 256, 512, "sparse", &variant);
  // The brick grid is 26 wide: empty-space skipping (and auto's filter where the device's is exact).
  EXPECT_EQ(variant, useHardwareFilter(ctx(), compiler(), "auto") ? "sun+env+multi+hwfilter+skip" : "sun+env+multi+skip");
  // The medium is in view (rays through the near blob go on across the empty cells to the far one).
  EXPECT_GT(pixelsShowingMedium(img, s.lights[1].radiance), 40);
}

// The viewer's density slider sets the scale of the device volume in place
// (GpuVolumeResources::setDensityScale): the image is bit-identical to one rendered from a volume
// built with that scale, differs from the old scale's, and the volume counts as a new one.
TEST_F(GpuPathTracer, DensityScaleSetInPlaceEqualsARebuiltVolume) {
  Scene s = baseScene({0.5f, 0.6f, 2.2f}, {0.5f, 0.5f, 0.5f}, 16);
  s.render.spp = 4;
  s.render.maxBounces = 3;
  LoadedGrid loaded;
  loaded.grid = test::makeBoxGrid(16, 1.0 / 16);
  loaded.name = "density";
  const BakedVolume bake = bakeVolume(loaded);
  auto render = [&](const GpuVolumeResources& volume) {
    PathTracer tracer(ctx(), compiler(), s);
    tracer.setVolume(volume);
    tracer.beginFrame(1);
    tracer.addSamples(s.render.spp);
    return tracer.readImage();
  };
  GpuVolumeResources edited(ctx(), bake, 2.0f);
  const Image before = render(edited);
  const uint64_t serial = edited.serial();
  edited.setDensityScale(6.0f);
  EXPECT_NE(edited.serial(), serial);
  const Image after = render(edited);
  const Image rebuilt = render(GpuVolumeResources(ctx(), bake, 6.0f));
  EXPECT_EQ(after.rgb, rebuilt.rgb);
  EXPECT_NE(after.rgb, before.rgb);
}

// A generation traces several samples of every pixel at once (PathTracer::kGenerationPaths); each
// path's random stream is its pixel's and sample's and the resolve merges a pixel's samples in
// sample order, so the image (mean and variance, every bit) does not depend on how the samples
// are grouped into generations: all at once, one per call, or in uneven calls.
TEST_F(GpuPathTracer, SamplesGroupedInGenerationsGiveTheSameImage) {
  Scene s = denseCloudScene();
  LoadedGrid loaded;
  loaded.grid = test::makeBoxGrid(16, 1.0 / 16);
  loaded.name = "density";
  GpuVolumeResources volume(ctx(), bakeVolume(loaded), s.media[0].densityScale);
  auto render = [&](const std::vector<int>& calls, uint32_t* perGeneration = nullptr) {
    PathTracer tracer(ctx(), compiler(), s);
    tracer.setVolume(volume);
    tracer.beginFrame(3);
    for (int n : calls) tracer.addSamples(n);
    if (perGeneration) *perGeneration = tracer.samplesPerGeneration();
    return tracer.readImage();
  };
  uint32_t perGeneration = 0;
  const Image together = render({12}, &perGeneration);
  EXPECT_GE(perGeneration, 12u);  // 24² pixels: one generation holds all 12 samples
  const Image single = render(std::vector<int>(12, 1));
  const Image uneven = render({5, 7});
  EXPECT_EQ(single.rgb, together.rgb);
  EXPECT_EQ(single.var, together.var);
  EXPECT_EQ(uneven.rgb, together.rgb);
  EXPECT_EQ(uneven.var, together.var);
  EXPECT_GT(pixelsShowingMedium(together, together.pixel(0, 0)), 50);
}

// An image of more than PathTracer::kGenerationPaths pixels goes in bands of that many pixels,
// several samples each (session 25; one sample per band of 2^20 pixels before), and its
// accumulation in as many storage buffers as the device's limit needs (lavapipe's 128 MiB held
// 4.2 megapixels: `plume render` of 3840x2160 failed). Same image, every bit, whether the samples
// come together or one by one, and whether the accumulation is one buffer or split (a limit of one
// band per buffer here: two parts for 640x480); a split accumulation cannot be shown in place. The
// one-buffer image finishes the pixels whose rays all miss in its background pass (session 28),
// the split one traces them: the same bits either way.
TEST_F(GpuPathTracer, LargeImagesGoInBandsAndSplitAccumulationsGiveTheSameImage) {
  Scene s = denseCloudScene();
  s.camera.width = 640;
  s.camera.height = 480;
  s.render.maxBounces = 2;
  LoadedGrid loaded;
  loaded.grid = test::makeBoxGrid(16, 1.0 / 16);
  loaded.name = "density";
  GpuVolumeResources volume(ctx(), bakeVolume(loaded), s.media[0].densityScale);
  const VkDeviceSize oneBand = VkDeviceSize(PathTracer::kGenerationPaths) * 2 * sizeof(glm::vec4);
  auto render = [&](const std::vector<int>& calls, VkDeviceSize limit, size_t parts) {
    PathTracer tracer(ctx(), compiler(), s, false, limit);
    EXPECT_EQ(tracer.generationPixels(), PathTracer::kGenerationPaths);
    EXPECT_EQ(tracer.samplesPerGeneration(), PathTracer::kMaxSlots / PathTracer::kGenerationPaths);
    EXPECT_EQ(tracer.accumulationBands(), parts);
    if (parts > 1) EXPECT_THROW(tracer.accumulation(), InputError);
    tracer.setVolume(volume);
    tracer.beginFrame(2);
    for (int n : calls) tracer.addSamples(n);
    // One accumulation buffer: the pixels whose rays all miss the volume are finished by the
    // background pass, without slots; a split one traces every pixel (row order, no pixel list).
    const PassTimes& times = tracer.lastPassTimes();
    const bool background = std::any_of(times.begin(), times.end(), [](const auto& t) { return t.first == "pt background"; });
    EXPECT_EQ(background, parts == 1);
    return tracer.readImage();
  };
  const Image together = render({5}, 0, 1);
  const Image single = render({1, 1, 1, 1, 1}, 0, 1);
  const Image split = render({3, 2}, oneBand, 2);
  EXPECT_EQ(single.rgb, together.rgb);
  EXPECT_EQ(single.var, together.var);
  EXPECT_EQ(split.rgb, together.rgb);
  EXPECT_EQ(split.var, together.var);
  EXPECT_GT(pixelsShowingMedium(together, together.pixel(0, 0)), 5000);
  // Below one band per buffer there is no way to split: a clear error, not a crash.
  EXPECT_THROW(PathTracer(ctx(), compiler(), s, false, oneBand / 2), InputError);
}
