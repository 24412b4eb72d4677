// Surfaces in the GPU path tracer (issue 12; DESIGN §4.3): closed forms where the estimator is
// exact (a diffuse plane under a sun, an emitter seen directly, front and back), the per-pixel
// and aggregate Z-tests against the CPU reference (which intersects with Embree itself, not the
// flattened tree) on smoke over a ground, an occluder and a glossy conductor, and emissive quads
// as the only lights; and a scene without surfaces compiles no traversal and builds no BVH.
#include "render/features.h"
#include "render/gpu_surfaces.h"
#include "render/path_tracer.h"
#include "shaders/shared/bindings.h"
#include "support/gpu_fixture.h"
#include "support/grids.h"
#include "support/scenes.h"

#include <glm/glm.hpp>

#include <cmath>
#include <random>

using namespace plume;

namespace {

class GpuSurfaceTest : public test::GpuTest {};

Scene groundScene(int size, int bounces) { return test::smokeOverGroundScene(size, bounces); }

Surface emitter(glm::vec3 centre, glm::vec3 normal, glm::vec2 size, glm::vec3 radiance) {
  return test::emitterSurface(centre, normal, size, radiance);
}

void renderAndCompare(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const Scene& s, openvdb::FloatGrid::Ptr grid,
                      int gpuSpp, int refSpp, const std::string& name) {
  test::expectPtMatchesReference(ctx, compiler, s, grid, gpuSpp, refSpp, name, "gpu_surfaces", "surfaces");
}

// SPIR-V decorates a descriptor binding as OpDecorate (opcode 71) <id> Binding (33) <n>.
bool declaresBinding(const std::vector<uint32_t>& spirv, uint32_t binding) {
  for (size_t i = 5; i < spirv.size();) {
    const uint32_t words = spirv[i] >> 16, opcode = spirv[i] & 0xffffu;
    if (words == 0) break;
    if (opcode == 71 && words >= 4 && spirv[i + 2] == 33 && spirv[i + 3] == binding) return true;
    i += words;
  }
  return false;
}

}  // namespace

// No medium (an empty grid), a delta sun, one bounce: every sample that sees the plane returns
// exactly L = rho E cos(theta) / pi (next-event estimation is deterministic here), the others 0,
// so each pixel holds L times the fraction of its samples that hit the plane (1 below the horizon).
TEST_F(GpuSurfaceTest, DiffusePlaneUnderASunIsRhoECosOverPi) {
  Scene s = groundScene(24, 1);
  s.lights = {test::sunLight({0.3f, 1.0f, -0.2f}, {2.0f, 3.0f, 4.0f})};
  s.render.spp = 4;
  const Image img = test::renderGpuPt(ctx(), compiler(), s, openvdb::FloatGrid::create());
  const glm::vec3 rho = s.surfaces[0].albedo;
  const float cosTheta = glm::normalize(glm::vec3(0.3f, 1.0f, -0.2f)).y;
  const glm::vec3 expected = rho * glm::vec3(2.0f, 3.0f, 4.0f) * cosTheta / float(M_PI);
  int full = 0;
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      const glm::vec3 p = img.pixel(x, y);
      const float hits = std::round(p.x / expected.x * float(s.render.spp));
      ASSERT_GE(hits, 0.0f);
      ASSERT_LE(hits, float(s.render.spp));
      full += hits == float(s.render.spp);
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(p[c], expected[c] * hits / float(s.render.spp), 1e-5f * expected[c]) << x << "," << y << " channel " << c;
      }
    }
  }
  EXPECT_GT(full, img.width * img.height / 3);  // the lower part of the image
}

// An emitter seen directly returns its radiance from the front and nothing from the back.
TEST_F(GpuSurfaceTest, EmitterSeenDirectlyFrontAndBack) {
  for (const float side : {1.0f, -1.0f}) {
    Scene s = groundScene(16, 1);
    s.lights.clear();
    s.surfaces = {emitter(s.camera.base.lookAt, side * (s.camera.base.position - s.camera.base.lookAt), {20.0f, 20.0f},
                          {1.5f, 2.5f, 3.5f})};
    s.render.spp = 2;
    const Image img = test::renderGpuPt(ctx(), compiler(), s, openvdb::FloatGrid::create());
    const glm::vec3 expected = side > 0.0f ? glm::vec3(1.5f, 2.5f, 3.5f) : glm::vec3(0.0f);
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) ASSERT_EQ(img.pixel(x, y), expected) << x << "," << y << " side " << side;
  }
}

// Smoke over a diffuse ground under sun and sky: the smoke's shadow on the ground, the ground's
// light bounced into the smoke.
TEST_F(GpuSurfaceTest, SmokeOverGroundMatchesReference) {
  renderAndCompare(ctx(), compiler(), groundScene(24, 4), test::makeNoiseGrid(32, 1.0 / 16, 3), 512, 1024,
                   "smoke_over_ground");
}

// An occluding quad between the sun and the smoke, and a glossy conductor quad beside it.
TEST_F(GpuSurfaceTest, OccluderAndGlossyConductorMatchReference) {
  renderAndCompare(ctx(), compiler(), test::occluderAndConductorScene(24, 4), test::makeNoiseGrid(32, 1.0 / 16, 5), 512,
                   1024, "occluder_and_conductor");
}

// Emissive quads as the only lights (light sampling by area in proportion to power, BSDF and
// phase sampling hitting them, combined by MIS), with a back-facing one that must stay dark.
TEST_F(GpuSurfaceTest, EmissiveQuadsAsTheOnlyLightsMatchReference) {
  renderAndCompare(ctx(), compiler(), test::emissiveQuadsScene(24, 3), test::makeNoiseGrid(32, 1.0 / 16, 7), 4096, 8192,
                   "emissive_quads");
}

// DESIGN §5: a scene without surfaces compiles no traversal (no BVH binding in its kernels) and
// builds no BVH; with surfaces both kernels bind it.
TEST_F(GpuSurfaceTest, ASceneWithoutSurfacesCompilesNoTraversal) {
  Scene with = groundScene(8, 2);
  Scene without = with;
  without.surfaces.clear();
  EXPECT_FALSE(featuresOf(without).surfaces);
  EXPECT_TRUE(featuresOf(with).surfaces);
  for (const char* kernel : {"passes/pt_extend.comp", "passes/pt_shade.comp"}) {
    EXPECT_FALSE(declaresBinding(compiler().compile(kernel, featuresOf(without).defines()), shared::BIND_BVH_NODES))
        << kernel;
    EXPECT_TRUE(declaresBinding(compiler().compile(kernel, featuresOf(with).defines()), shared::BIND_BVH_NODES))
        << kernel;
  }
  EXPECT_FALSE(PathTracer(ctx(), compiler(), without).hasSurfaces());
  EXPECT_TRUE(PathTracer(ctx(), compiler(), with).hasSurfaces());
}

// The emitters' alias table chooses triangle i with probability w_i / sum w: the probability each
// entry implies (its own keep, plus the rest of every entry that hands over to it, over n) equals
// the weight's share, for spread, equal and one-dominant weights.
TEST(EmitterAliasTable, ChoosesEachTriangleInProportionToItsWeight) {
  std::mt19937 gen(7);
  std::uniform_real_distribution<double> logw(-3.0, 3.0);
  std::vector<std::vector<double>> cases = {{}, std::vector<double>(50, 2.0), {1e6, 1.0, 1.0, 1.0}, {3.0}};
  for (int i = 0; i < 1000; ++i) cases[0].push_back(std::pow(10.0, logw(gen)));
  for (const std::vector<double>& w : cases) {
    std::vector<uint32_t> triangles(w.size());
    for (size_t i = 0; i < w.size(); ++i) triangles[i] = uint32_t(1000 + 3 * i);
    const std::vector<shared::GpuEmitterAlias> table = emitterAliasTable(w, triangles);
    ASSERT_EQ(table.size(), w.size());
    std::vector<double> p(w.size(), 0.0);
    for (size_t i = 0; i < table.size(); ++i) {
      ASSERT_EQ(table[i].triangle, triangles[i]);
      ASSERT_GE(table[i].keep, 0.0f);
      ASSERT_LE(table[i].keep, 1.0f);
      ASSERT_LT(table[i].alias, table.size());
      p[i] += double(table[i].keep) / double(w.size());
      p[table[i].alias] += (1.0 - double(table[i].keep)) / double(w.size());
    }
    double total = 0.0;
    for (double x : w) total += x;
    for (size_t i = 0; i < w.size(); ++i) EXPECT_NEAR(p[i], w[i] / total, 1e-7 + 1e-6 * w[i] / total) << i << " of " << w.size();
  }
}
