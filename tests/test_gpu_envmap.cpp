// Environment maps on the device (DESIGN §2, §7): tier c, shared/envmap.h compiled as GLSL gives
// the C++ results on the same map and inputs; the orientation convention as a camera sees it;
// a constant map renders as the constant environment light; and tier d, the GPU path tracer
// (map NEE with power-heuristic MIS against phase sampling) against the independent CPU
// reference: a smoke-like cloud under the bundled sky (volumes/sky/sky.exr, a sun disk in the
// map) and under a rotated, tilted map. Validation layers are on. ReSTIR's checks are in
// test_restir.cpp.
#include "gpu/pipeline.h"
#include "io/image.h"
#include "media/vdb_loader.h"
#include "reference/reference.h"
#include "render/gpu_envmap.h"
#include "shaders/shared/envmap.h"
#include "shaders/shared/rng.h"
#include "shaders/shared/sampling.h"
#include "support/gpu_fixture.h"
#include "support/grids.h"
#include "support/reference_check.h"
#include "support/scenes.h"
#include "support/test_support.h"

#include <glm/glm.hpp>

#include <filesystem>

using namespace plume;
namespace sh = plume::shared;

namespace {

class GpuEnvMap : public test::GpuTest {};

Light mapLight(const std::string& path, glm::vec3 up = {0, 1, 0}, float rotateYDeg = 0.0f, float scale = 1.0f) {
  Light l = test::skyLight(glm::vec3(0));
  l.map = path;
  l.up = up;
  l.rotateYDeg = rotateYDeg;
  l.scale = scale;
  return l;
}

std::string skyPath() { return test::sourcePath("volumes/sky/sky.exr"); }

Scene cloudScene(int size) {
  Scene s = test::sceneWithCamera("test-scene", {1.0f, 1.2f, 4.0f}, {1.0f, 1.0f, 1.0f}, size);
  Medium m;
  m.densityScale = 4.0f;
  m.albedo = glm::vec3(0.9f);
  m.g = 0.3f;
  s.media.push_back(m);
  s.render.maxBounces = 4;
  return s;
}

void expectPtMatchesReference(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const Scene& s,
                              openvdb::FloatGrid::Ptr grid, int gpuSpp, int refSpp, const std::string& name) {
  test::expectPtMatchesReference(ctx, compiler, s, grid, gpuSpp, refSpp, name, "gpu_envmap", "envmap");
}

}  // namespace

// Tier c: env_sample, env_pdf and env_radiance on the device equal the C++ ones on the bundled
// sky, rotated and tilted (binary searches, atan/acos and the rotation included).
TEST_F(GpuEnvMap, GlslSamplerEqualsCpp) {
  const EnvMapData d = buildEnvMapData(loadEnvironmentMap(skyPath(), "sky"), 1.0f, glm::vec3(0.1f, 1.0f, -0.2f), 63.0f);
  struct EnvCase {
    glm::vec4 u, dir;
  };
  struct EnvResult {
    glm::vec4 sampled, lookup;
  };
  const int n = 4096;
  std::vector<EnvCase> cases(n);
  sh::RngState rng = sh::rng_init(glm::uvec2(9, 9), 1u, sh::RNG_STREAM_TEST, 17u);
  for (int i = 0; i < n; ++i) {
    cases[i].u = glm::vec4(sh::rng_float2(rng), 0.0f, 0.0f);
    cases[i].dir = glm::vec4(sh::smp_uniform_sphere(sh::rng_float2(rng)), 0.0f);
  }
  cases[0].u = glm::vec4(0.0f);
  cases[1].u = glm::vec4(0.99999994f, 0.99999994f, 0, 0);
  using gpu::BindingType;
  gpu::ComputePass pass(ctx(), compiler().compile("tests/envmap_kernels.comp", {}),
                        {BindingType::StorageBuffer, BindingType::StorageBuffer, BindingType::StorageBuffer}, 4,
                        "envmap kernels", glm::uvec3(64, 1, 1));
  const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  gpu::Buffer map(ctx(), sizeof(d.header) + d.data.size() * sizeof(float), storage, "map");
  map.upload(&d.header, sizeof(d.header));
  map.upload(d.data.data(), d.data.size() * sizeof(float), sizeof(d.header));
  gpu::Buffer in(ctx(), n * sizeof(EnvCase), storage, "cases");
  gpu::Buffer out(ctx(), n * sizeof(EnvResult), storage, "results");
  in.upload(cases.data(), n * sizeof(EnvCase));
  pass.set.bind(0, map);
  pass.set.bind(1, in);
  pass.set.bind(2, out);
  const uint32_t count = n;
  ctx().submitAndWait([&](VkCommandBuffer cmd) { pass.record(cmd, glm::uvec3(n, 1, 1), &count); });
  std::vector<EnvResult> g(n);
  out.download(g.data(), n * sizeof(EnvResult));
  auto near = [](float a, float b, float rel) { return std::abs(a - b) <= rel * std::max(1.0f, std::abs(b)); };
  // Within 1e-3 of a texel's edge (in texels), float rounding of atan/acos may pick either
  // texel on the device or the host: such directions are counted, not compared.
  auto nearEdge = [&](glm::vec3 w) {
    const glm::vec2 uv = sh::env_local_uv(sh::env_to_local(d.header, w));
    const glm::vec2 t = uv * glm::vec2(d.header.width, d.header.height);
    const glm::vec2 f = t - glm::floor(t);
    return glm::min(glm::min(f.x, 1.0f - f.x), glm::min(f.y, 1.0f - f.y)) < 1e-3f;
  };
  int dirMismatch = 0, pdfMismatch = 0, lookupMismatch = 0, sunSamples = 0, edges = 0;
  for (int i = 0; i < n; ++i) {
    const glm::vec3 w = sh::env_sample(d.data.data(), d.header, glm::vec2(cases[i].u));
    const float pdf = sh::env_pdf(d.data.data(), d.header, w);
    bool ok = true;
    for (int a = 0; a < 3; ++a) ok = ok && near(g[i].sampled[a], w[a], 1e-4f);
    dirMismatch += !ok;
    const glm::vec3 dir(cases[i].dir);
    if (nearEdge(w) || nearEdge(glm::vec3(g[i].sampled)) || nearEdge(dir)) {
      ++edges;
      continue;
    }
    pdfMismatch += !near(g[i].sampled.w, pdf, 1e-4f);
    const glm::vec3 L = sh::env_radiance(d.data.data(), d.header, dir);
    const bool bad = !near(g[i].lookup.w, sh::env_pdf(d.data.data(), d.header, dir), 1e-4f) ||
                      !near(g[i].lookup.x, L.x, 1e-6f) || !near(g[i].lookup.y, L.y, 1e-6f) ||
                      !near(g[i].lookup.z, L.z, 1e-6f);
    if (bad && lookupMismatch < 5) {
      const glm::vec3 loc = sh::env_to_local(d.header, dir);
      const glm::vec2 uv = sh::env_local_uv(loc);
      std::printf("lookup %d: dir %g %g %g local %g %g %g uv %g %g: gpu %g %g %g pdf %g, cpu %g %g %g pdf %g\n", i, dir.x, dir.y, dir.z,
                  loc.x, loc.y, loc.z, uv.x * 512, uv.y * 256, g[i].lookup.x, g[i].lookup.y, g[i].lookup.z, g[i].lookup.w, L.x, L.y, L.z,
                  sh::env_pdf(d.data.data(), d.header, dir));
    }
    lookupMismatch += bad;
    sunSamples += pdf > 50.0f;
  }
  EXPECT_EQ(dirMismatch, 0);
  EXPECT_EQ(pdfMismatch, 0);
  EXPECT_EQ(lookupMismatch, 0);
  EXPECT_LT(edges, n / 50);
  EXPECT_GT(sunSamples, n / 10) << "the sky's sun disk should take a good share of the samples";
}

// A camera looking along the direction DESIGN §2 predicts for a map's one bright texel sees it
// in its centre pixel (an empty volume: camera rays escape). With up = +Z and rotate_y_deg = 90,
// M maps world (x, y, z) to (x, z, -y) and R_y(-90 deg) maps (x, y, z) to (-z, y, x), so world
// (x, y, z) reads the map at local (y, z, x) (worked by hand; test_envmap.cpp checks the same
// algebra on the CPU). Without the rotation the same world direction reads another texel.
TEST_F(GpuEnvMap, CameraSeesTheTexelWhereDesignPutsIt) {
  const int W = 64, H = 32;
  Image im(W, H);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) im.setPixel(x, y, glm::vec3(0.01f));
  im.setPixel(W / 4, H / 4, glm::vec3(50.0f, 40.0f, 30.0f));
  const std::string path = (std::filesystem::path(test::outputDir("gpu_envmap_orientation")) / "one_texel.exr").string();
  writeExr(path, im);
  // The texel's centre in the local frame, then in the world by local = (y_w, z_w, x_w).
  const double theta = M_PI * (H / 4 + 0.5) / H, phi = 2.0 * M_PI * (W / 4 + 0.5) / W;
  const glm::dvec3 local(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
  const glm::vec3 world(float(local.z), float(local.x), float(local.y));
  initOpenVdb();
  auto grid = openvdb::FloatGrid::create(0.0f);
  for (float rot : {90.0f, 0.0f}) {
    Scene s = cloudScene(9);
    s.camera.base.position = glm::vec3(0.0f);
    s.camera.base.lookAt = world;
    s.camera.base.up = glm::vec3(0.3f, 0.2f, 1.0f);
    s.camera.base.fovY = 3.0f;  // about one texel across the image
    s.lights = {mapLight(path, {0, 0, 1}, rot)};
    s.render.spp = 16;
    const Image img = test::renderGpuPt(ctx(), compiler(), s, grid);
    const glm::vec3 centre = img.pixel(4, 4);
    if (rot == 90.0f) {
      EXPECT_EQ(centre, glm::vec3(50.0f, 40.0f, 30.0f)) << "up +Z, rotate_y_deg 90";
    } else {
      EXPECT_EQ(centre, glm::vec3(0.01f)) << "without the rotation the texel is elsewhere";
    }
  }
}

// A constant map (sampled by its texels, MIS with phase sampling, escaped paths weighted) and the
// constant environment light (phase sampling) give the same image on the GPU.
TEST_F(GpuEnvMap, ConstantMapEqualsConstantEnvironment) {
  const glm::vec3 L(0.3f, 0.4f, 0.5f);
  Image im(16, 8);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 16; ++x) im.setPixel(x, y, L * 0.25f);
  const std::string path = (std::filesystem::path(test::outputDir("gpu_envmap_constant")) / "constant.exr").string();
  writeExr(path, im);
  auto grid = test::makeNoiseGrid(40, 1.0 / 20, 5);
  Scene s = cloudScene(16);
  s.render.spp = 512;
  Scene sMap = s;
  s.lights = {test::skyLight(L)};
  sMap.lights = {mapLight(path, {1, 1, 0}, 10.0f, 4.0f)};
  sMap.render.seed = 7;
  test::GpuRenderInfo a, b;
  const Image constant = test::renderGpuPt(ctx(), compiler(), s, grid, 1, &a);
  const Image mapped = test::renderGpuPt(ctx(), compiler(), sMap, grid, 1, &b);
  EXPECT_EQ(a.variant.find("envmap"), std::string::npos) << a.variant;
  EXPECT_NE(b.variant.find("envmap"), std::string::npos) << b.variant;
  test::ReferenceCheckOptions options;
  options.outputGroup = "gpu_envmap";
  test::expectMatchesReference(mapped, constant, "constant_map", options);
}

// Tier d: the bundled sky (a 2-degree sun disk of irradiance 3 in a dim gradient sky: most of
// the light comes from a few texels) over a cloud, several bounces.
TEST_F(GpuEnvMap, PathTracerUnderSkyMatchesReference) {
  Scene s = cloudScene(16);
  s.lights = {mapLight(skyPath())};
  expectPtMatchesReference(ctx(), compiler(), s, test::makeNoiseGrid(40, 1.0 / 20, 6), 256, 1024, "sky");
}

// A rotated and tilted map, single scattering (the variant whose path follows its phase sample
// only to see the map) and a constant environment beside it.
TEST_F(GpuEnvMap, PathTracerUnderRotatedMapMatchesReference) {
  Scene s = cloudScene(16);
  s.lights = {mapLight(skyPath(), {0.3f, 0.2f, 1.0f}, 140.0f, 1.5f), test::skyLight({0.02f, 0.03f, 0.04f})};
  s.render.maxBounces = 1;
  expectPtMatchesReference(ctx(), compiler(), s, test::makeNoiseGrid(40, 1.0 / 20, 7), 256, 1024, "rotated");
}
