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
#include "support/light_tree.h"
#include "support/scenes.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
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
    EXPECT_FALSE(declaresBinding(compiler().compile(kernel, featuresOf(without).defines()), shared::BIND_BVH))
        << kernel;
    EXPECT_TRUE(declaresBinding(compiler().compile(kernel, featuresOf(with).defines()), shared::BIND_BVH))
        << kernel;
  }
  EXPECT_FALSE(PathTracer(ctx(), compiler(), without).hasSurfaces());
  EXPECT_TRUE(PathTracer(ctx(), compiler(), with).hasSurfaces());
}

// The importance's distance term (shared/light_tree.h lt_importance): for a node that emits in
// every direction, seen from a point with no receiver, it is the node's power times the mean of
// 1 / d² over its bounding sphere as a uniform ball, 3/4 (2 + (1 - a²)/a ln|(1 + a)/(1 - a)|) / r²
// at a = D / r, approximated within 37% (1.36x at most, at a = 0.82; exact at the centre, on the sphere and far off), and
// continuous across the sphere.
TEST(LightTree, DistanceTermIsTheMeanOfInverseSquareDistanceOverTheSphere) {
  shared::GpuLightNode nd{};
  const float r = 0.5f;
  nd.boxMin = glm::vec3(-r / std::sqrt(3.0f));
  nd.boxMax = glm::vec3(r / std::sqrt(3.0f));
  nd.power = 2.0f;
  nd.axis = glm::vec3(0.0f, 0.0f, 1.0f);
  nd.cosCone = -1.0f;
  nd.child = shared::LT_LEAF;
  const glm::vec3 dir = glm::normalize(glm::vec3(0.3f, -0.8f, 0.5f));
  auto exact = [](double a) {
    if (a < 1e-9) return 3.0;
    if (std::abs(a - 1.0) < 1e-9) return 1.5;
    return 0.75 * (2.0 + (1.0 - a * a) / a * std::log(std::abs((1.0 + a) / (1.0 - a))));
  };
  double worst = 1.0;
  int checked = 0;
  for (int k = 0; k <= 400; ++k) {
    const double a = 0.025 * k;  // D / r from 0 to 10
    const float got = shared::lt_importance(nd, float(a * r) * dir, glm::vec3(0.0f));
    const double want = nd.power * exact(a) / (double(r) * r);
    const double ratio = double(got) / want;
    worst = std::max(worst, std::max(ratio, 1.0 / ratio));
    ++checked;
    if (k == 0 || k == 40 || k == 400) EXPECT_NEAR(ratio, 1.0, 2e-3) << "a = " << a;  // exact there
  }
  EXPECT_EQ(checked, 401);
  EXPECT_LT(worst, 1.37) << "the approximation's largest error over a in [0, 10]";
  // Continuous across the sphere: just inside and just outside agree.
  const float in = shared::lt_importance(nd, (r * 0.9999f) * dir, glm::vec3(0.0f));
  const float out = shared::lt_importance(nd, (r * 1.0001f) * dir, glm::vec3(0.0f));
  EXPECT_NEAR(in / out, 1.0f, 1e-3f);
}

// The descent's steps (shared/light_tree.h lt_step): from a node, one of its grandchildren (a child
// that is a leaf standing for itself) in proportion to its importance, two levels a step. An
// independent walk over the whole tree with that rule gives every emitter's probability, which
// lt_pmf must equal, for trees of 2 to 1000 random emitters (leaves at odd and even depths) at
// random points in a medium and on surfaces. (The binary rule, one level a step, fails it, and so
// does lt_pmf with the grandchildren's probabilities swapped within a pair.)
TEST(LightTree, EachStepPicksAGrandchildByItsImportance) {
  std::mt19937 gen(11);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  auto point = [&](float r) { return r * glm::vec3(2.0f * u01(gen) - 1.0f, 2.0f * u01(gen) - 1.0f, 2.0f * u01(gen) - 1.0f); };
  int compared = 0;
  int leafBesideInner = 0;  // steps where one child is a leaf and its sibling is not
  double worst = 0.0;       // the largest relative difference
  for (const int n : {2, 3, 5, 6, 1000}) {
    std::vector<LightTreeEmitter> e;
    for (int i = 0; i < n; ++i) {
      const glm::vec3 c = point(3.0f);
      const float size = std::pow(10.0f, -2.0f + 1.5f * u01(gen));
      e.push_back({c + point(size), c + point(size), c + point(size), std::pow(10.0, 2.0 * u01(gen)), uint32_t(i)});
    }
    const LightTree tree = buildLightTree(e);
    test::ltTestNodes = &tree.nodes;
    const auto& nodes = tree.nodes;
    for (int k = 0; k < 50; ++k) {
      const glm::vec3 x = point(4.0f);
      const glm::vec3 r = k % 2 == 0 ? glm::vec3(0.0f) : glm::normalize(point(1.0f) + glm::vec3(1e-3f));
      std::vector<double> want(size_t(n), 0.0);
      // From node i with probability p: the candidates and their importances.
      std::function<void(uint32_t, double)> walk = [&](uint32_t i, double p) {
        const shared::GpuLightNode& nd = nodes[i];
        if (nd.child & shared::LT_LEAF) {
          want[nd.child & ~shared::LT_LEAF] = p;
          return;
        }
        std::vector<uint32_t> cand;
        if (((nodes[nd.child].child ^ nodes[nd.child + 1u].child) & shared::LT_LEAF) != 0u) ++leafBesideInner;
        for (const uint32_t c : {nd.child, nd.child + 1u}) {
          if (nodes[c].child & shared::LT_LEAF) {
            cand.push_back(c);
          } else {
            cand.push_back(nodes[c].child);
            cand.push_back(nodes[c].child + 1u);
          }
        }
        double total = 0.0;
        for (const uint32_t c : cand) total += shared::lt_importance(nodes[c], x, r);
        if (!(total > 0.0)) return;
        for (const uint32_t c : cand) {
          const double w = shared::lt_importance(nodes[c], x, r);
          if (w > 0.0) walk(c, p * w / total);
        }
      };
      walk(0u, 1.0);
      for (int i = 0; i < n; ++i) {
        // float arithmetic over up to ~10 steps, 1 - p where p is near 1 among them (1e-4 seen)
        const double got = shared::lt_pmf(x, r, tree.trails[size_t(i)]);
        EXPECT_NEAR(got, want[size_t(i)], 1e-3 * want[size_t(i)] + 1e-12) << "emitter " << i << " of " << n;
        if (want[size_t(i)] > 0.0) worst = std::max(worst, std::abs(got / want[size_t(i)] - 1.0));
        ++compared;
      }
    }
  }
  EXPECT_EQ(compared, 50 * (2 + 3 + 5 + 6 + 1000));
  EXPECT_GT(leafBesideInner, 0) << "no step had a leaf child beside an inner one";
  std::printf("largest relative difference from the walk: %.3g; steps with a leaf beside an inner child: %d\n", worst,
              leafBesideInner);
}

// The light tree (shared/light_tree.h, built by buildLightTree) over random emitters of every
// orientation and size: at random shading points, in a medium (no receiver normal) and on a
// surface (a random receiver normal), the probabilities of all emitters (lt_pmf, from their trails)
// sum to at most 1, every emitter that faces the point and (on a surface) lies in front of its
// normal — at a corner or its centroid — has a nonzero probability (the importance bound is
// conservative: a zero would be a bias), and the descent (lt_sample) returns the probability
// lt_pmf gives its triangle. (CityEmitters.LightTree... checks the descent's frequencies.) Also for
// one emitter, and for many emitters on one spot (a degenerate split). The receiver bound must
// also prune: on a surface, an emitter well behind it and far from it has probability 0.
TEST(LightTree, ProbabilitiesSumToOneAndReachEveryEmitterThatFacesThePoint) {
  std::mt19937 gen(7);
  int prunedChecks = 0;  // emitters checked to be pruned by the receiver bound
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  auto point = [&](float r) { return r * glm::vec3(2.0f * u01(gen) - 1.0f, 2.0f * u01(gen) - 1.0f, 2.0f * u01(gen) - 1.0f); };
  for (const int n : {1, 2, 3, 1000, 4096}) {
    for (const bool onOneSpot : {false, true}) {
      std::vector<LightTreeEmitter> e;
      for (int i = 0; i < n; ++i) {
        const glm::vec3 c = onOneSpot ? glm::vec3(0.5f) : point(4.0f);
        const float size = std::pow(10.0f, -3.0f + 2.5f * u01(gen));
        e.push_back({c + point(size), c + point(size), c + point(size), std::pow(10.0, 3.0 * u01(gen)), uint32_t(5 * i + 1)});
      }
      const LightTree tree = buildLightTree(e);
      ASSERT_EQ(tree.nodes.size(), size_t(2 * n - 1));
      // The SAOH build may be deeper than a balanced tree (here up to 28 levels for emitters on
      // one spot), never past the trails' 32 bits: every leaf's marker bit at most 30.
      EXPECT_LE(tree.depth, 30) << n;
      EXPECT_GE(tree.depth, int(std::ceil(std::log2(double(n))))) << n;
      for (const uint32_t trail : tree.trails) EXPECT_TRUE(trail != 0u && trail < (1u << 31)) << trail;
      test::ltTestNodes = &tree.nodes;
      for (int k = 0; k < 400; ++k) {
        const glm::vec3 x = point(6.0f);
        // Every other point on a surface: a receiver normal, light only from its side.
        const glm::vec3 r = k % 2 == 0 ? glm::vec3(0.0f) : glm::normalize(point(1.0f) + glm::vec3(1e-3f));
        const bool onSurface = k % 2 == 1;
        double sum = 0.0;
        for (int i = 0; i < n; ++i) {
          const float p = shared::lt_pmf(x, r, tree.trails[i]);
          sum += p;
          const glm::vec3 nrm = glm::cross(e[i].v1 - e[i].v0, e[i].v2 - e[i].v0);
          const glm::vec3 c = (e[i].v0 + e[i].v1 + e[i].v2) / 3.0f;
          bool reaches = false;
          bool behind = true;
          for (const glm::vec3 q : {e[i].v0, e[i].v1, e[i].v2, c}) {
            const bool faces = glm::dot(nrm, x - q) > 1e-6f * glm::length(nrm) * glm::length(x - q);
            const bool inFront = !onSurface || glm::dot(r, q - x) > 1e-6f * glm::length(q - x);
            reaches = reaches || (faces && inFront);
            behind = behind && onSurface && glm::dot(r, q - x) < -0.3f * glm::length(q - x);
          }
          if (reaches) {
            EXPECT_GT(p, 0.0f) << "emitter " << i << " of " << n << " lights the point but cannot be picked";
          }
          // A triangle is convex: all its corners well behind the receiver, so is all of it; the
          // leaf's bound (the triangle's own box) must then give 0 unless x is inside its sphere.
          const glm::vec3 lo = glm::min(e[i].v0, glm::min(e[i].v1, e[i].v2));
          const glm::vec3 hi = glm::max(e[i].v0, glm::max(e[i].v1, e[i].v2));
          const float radius = 0.5f * glm::length(hi - lo);
          const bool farFromBox = glm::length(x - 0.5f * (lo + hi)) > 20.0f * radius;
          // (A tree of one emitter has no choice to make: its pmf is 1, and a light sample that
          // cannot light x is merely wasted.)
          if (behind && farFromBox && n > 1) {
            EXPECT_EQ(p, 0.0f) << "emitter " << i << " of " << n << " lies behind the receiver";
            ++prunedChecks;
          }
        }
        // Below 1 where the descent can reach a node none of whose emitters faces x (it then
        // returns no sample: nothing was lost that could light x).
        EXPECT_LE(sum, 1.0 + 1e-4) << n;
        const float u = u01(gen);
        float pmf = 0.0f;
        const uint32_t tri = shared::lt_sample(x, r, u, pmf);
        if (!(pmf > 0.0f)) continue;
        const auto it = std::find_if(e.begin(), e.end(), [&](const LightTreeEmitter& m) { return m.triangle == tri; });
        ASSERT_NE(it, e.end());
        EXPECT_NEAR(pmf, shared::lt_pmf(x, r, tree.trails[size_t(it - e.begin())]), 1e-5f * pmf);
      }
    }
  }
  std::printf("emitters checked to be pruned behind a receiver: %d\n", prunedChecks);
  EXPECT_GT(prunedChecks, 100000);  // the pruning check is not vacuous
}
