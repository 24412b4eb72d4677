// The CPU reference with surfaces (issue 12), against closed forms:
//  - a diffuse plane under a sun, no medium: every pixel is rho E cos(theta) / pi (the estimator is
//    deterministic there: one NEE, and the bounce escapes into a black sky), and exactly 0 in the
//    shadow of a black square;
//  - an emissive quad seen directly is exactly its radiance from the front, black from the back;
//  - an emissive square lighting a diffuse ground: each pixel against rho Le F, F the closed-form
//    form factor from a point to a parallel rectangle, averaged over the pixel's footprint; with
//    emitter sampling alone, direction sampling alone and MIS (each is unbiased, so all three must
//    agree with it and with each other, also on a glossy conductor where no closed form exists);
//  - the same three estimators agree in smoke lit from below by an emitter (medium vertices);
//  - smoke over a plane: finite, the ground darker in the smoke's shadow than in the sun, and a
//    brighter ground brightens the smoke (light bounced into it).
#include "geometry/bvh.h"
#include "reference/reference.h"
#include "support/grids.h"
#include "support/reference_check.h"
#include "support/test_support.h"
#include "io/image.h"

#include <glm/glm.hpp>
#include <gtest/gtest.h>

#include <cmath>

using namespace plume;
using glm::dvec3;

namespace {

Scene sceneLookingAt(glm::vec3 position, glm::vec3 lookAt, glm::vec3 up, float fovY, int size) {
  Scene s;
  s.path = "test-scene";
  s.camera.base.position = position;
  s.camera.base.lookAt = lookAt;
  s.camera.base.up = up;
  s.camera.base.fovY = fovY;
  s.camera.width = s.camera.height = size;
  s.media.push_back(Medium{});
  return s;
}

Surface plane(glm::vec3 centre, glm::vec3 normal, glm::vec2 size, glm::vec3 albedo) {
  Surface s;
  s.plane = SurfacePlane{centre, normal, size};
  s.albedo = albedo;
  return s;
}

Surface emitter(glm::vec3 centre, glm::vec3 normal, glm::vec2 size, glm::vec3 radiance) {
  Surface s = plane(centre, normal, size, glm::vec3(0.0f));
  s.emission = radiance;
  return s;
}

openvdb::FloatGrid::ConstPtr noMedium() { return openvdb::FloatGrid::create(0.0f); }

Image render(const Scene& scene, openvdb::FloatGrid::ConstPtr grid,
             ref::EmitterStrategy strategy = ref::EmitterStrategy::Mis, ref::ReferenceStats* stats = nullptr) {
  ref::ReferenceOptions opt;
  opt.progress = false;
  opt.emitterStrategy = strategy;
  return ref::renderReference(scene, grid, opt, stats);
}

test::ReferenceCheckOptions checkOptions() {
  test::ReferenceCheckOptions options;
  options.outputGroup = "reference_surfaces";
  return options;
}

// DESIGN §2's pinhole: the camera ray through image point (px + u, py + v), row 0 at the top.
dvec3 cameraDirection(const Scene& s, double x, double y) {
  const CameraPose& p = s.camera.base;
  const dvec3 forward = glm::normalize(dvec3(p.lookAt - p.position));
  const dvec3 right = glm::normalize(glm::cross(forward, dvec3(p.up)));
  const dvec3 up = glm::cross(right, forward);
  const double tanHalf = std::tan(glm::radians(double(p.fovY)) * 0.5);
  const double aspect = double(s.camera.width) / s.camera.height;
  const double sx = (2.0 * x / s.camera.width - 1.0) * tanHalf * aspect;
  const double sy = (1.0 - 2.0 * y / s.camera.height) * tanHalf;
  return glm::normalize(forward + sx * right + sy * up);
}

// Where the camera ray through image point (x, y) meets the plane y = height (going down).
dvec3 groundPoint(const Scene& s, double x, double y, double height = 0.0) {
  const dvec3 o(s.camera.base.position), d = cameraDirection(s, x, y);
  return o + ((height - o.y) / d.y) * d;
}

}  // namespace

TEST(ReferenceSurfaces, DiffusePlaneUnderSunIsRhoECosOverPiOutsideAnOccludersShadow) {
  Scene s = sceneLookingAt({0.3f, 2.0f, 2.0f}, {0.0f, 0.0f, 0.0f}, {0, 1, 0}, 30.0f, 16);
  const glm::vec3 albedo(0.3f, 0.5f, 0.7f);
  s.surfaces.push_back(plane({0, 0, 0}, {0, 1, 0}, {100, 100}, albedo));
  // A black square at height 3, above the camera (out of its view), whose shadow along the sun
  // (0.4, 1, 0.3) is the square [-0.5, 0.5]^2 of the ground.
  s.surfaces.push_back(plane({1.2f, 3.0f, 0.9f}, {0, -1, 0}, {1, 1}, glm::vec3(0.0f)));
  Light sun;
  sun.type = LightType::Sun;
  sun.toLight = glm::normalize(glm::vec3(0.4f, 1.0f, 0.3f));
  sun.irradiance = {2.0f, 3.0f, 4.0f};
  s.lights.push_back(sun);
  s.render.maxBounces = 4;
  s.render.spp = 4;
  const Image img = render(s, noMedium());
  const double cosTheta = glm::normalize(dvec3(0.4, 1.0, 0.3)).y;
  int lit = 0, shadowed = 0;
  for (int py = 0; py < img.height; ++py) {
    for (int px = 0; px < img.width; ++px) {
      // A pixel is wholly in the shadow, or wholly out of it, when its footprint's corners are.
      int inside = 0;
      for (int corner = 0; corner < 4; ++corner) {
        const dvec3 p = groundPoint(s, px + (corner & 1), py + (corner >> 1));
        inside += std::abs(p.x) < 0.5 && std::abs(p.z) < 0.5;
      }
      if (inside != 0 && inside != 4) continue;
      ++(inside == 4 ? shadowed : lit);
      for (int c = 0; c < 3; ++c) {
        const size_t i = (size_t(py) * img.width + px) * 3 + size_t(c);
        const double expected = inside == 4 ? 0.0 : double(albedo[c]) * sun.irradiance[c] * cosTheta / M_PI;
        ASSERT_NEAR(img.rgb[i], expected, 1e-6 * expected) << "pixel " << px << "," << py << " channel " << c;
        ASSERT_LE(img.var[i], 1e-12 * expected * expected);
      }
    }
  }
  EXPECT_GT(lit, 50);
  EXPECT_GT(shadowed, 20);
}

TEST(ReferenceSurfaces, EmissiveQuadSeenDirectlyIsItsRadianceFromTheFrontOnly) {
  const glm::vec3 le(1.5f, 2.5f, 3.5f);
  Scene front = sceneLookingAt({0.2f, 0.1f, 3.0f}, {0, 0, 0}, {0, 1, 0}, 20.0f, 8);
  front.surfaces.push_back(emitter({0, 0, 0}, {0, 0, 1}, {4, 4}, le));
  front.render.spp = 8;
  const Image a = render(front, noMedium());
  for (size_t i = 0; i < a.rgb.size(); ++i) ASSERT_EQ(a.rgb[i], le[int(i % 3)]) << "value " << i;

  Scene back = front;
  back.camera.base.position = {0.2f, 0.1f, -3.0f};
  const Image b = render(back, noMedium());
  for (size_t i = 0; i < b.rgb.size(); ++i) ASSERT_EQ(b.rgb[i], 0.0f) << "value " << i;
}

namespace {

// Form factor from a differential area to a parallel rectangle at distance 1 with one corner
// straight above it, of sides a and b (Howell's catalogue, B-3): odd in a and in b, so a signed
// sum over the four corners gives any rectangle.
double cornerFormFactor(double a, double b) {
  const double ra = std::sqrt(1.0 + a * a), rb = std::sqrt(1.0 + b * b);
  return (a / ra * std::atan(b / ra) + b / rb * std::atan(a / rb)) / (2.0 * M_PI);
}

// A square emitter of side `side` at height h above the ground, centred over the origin and
// facing down; the ground is diffuse with albedo rho. The camera looks at the ground under it
// from below the emitter's height (the emitter's back, black, stays out of view).
struct LitGround {
  double side = 1.0, h = 1.0;
  glm::vec3 le{2.0f, 3.0f, 4.0f};
  glm::vec3 rho{0.5f, 0.6f, 0.7f};
  Scene scene = sceneLookingAt({2.5f, 0.6f, 0.4f}, {0.0f, 0.0f, 0.0f}, {0, 1, 0}, 10.0f, 8);

  LitGround() {
    scene.surfaces.push_back(plane({0, 0, 0}, {0, 1, 0}, {20, 20}, rho));
    scene.surfaces.push_back(emitter({0, float(h), 0}, {0, -1, 0}, {float(side), float(side)}, le));
    scene.render.maxBounces = 3;
  }

  // Irradiance / Le at ground point (x, 0, z): pi times the form factor to the emitter.
  double formFactor(double x, double z) const {
    const double x0 = (-0.5 * side - x) / h, x1 = (0.5 * side - x) / h;
    const double z0 = (-0.5 * side - z) / h, z1 = (0.5 * side - z) / h;
    return cornerFormFactor(x1, z1) - cornerFormFactor(x0, z1) - cornerFormFactor(x1, z0) + cornerFormFactor(x0, z0);
  }

  // Each pixel's radiance rho Le F, averaged over its footprint (16 x 16 midpoints).
  std::vector<float> exact() const {
    const Scene& s = scene;
    std::vector<float> out(size_t(s.camera.width) * s.camera.height * 3);
    constexpr int kSub = 16;
    for (int py = 0; py < s.camera.height; ++py) {
      for (int px = 0; px < s.camera.width; ++px) {
        double f = 0.0;
        for (int j = 0; j < kSub; ++j) {
          for (int i = 0; i < kSub; ++i) {
            const dvec3 p = groundPoint(s, px + (i + 0.5) / kSub, py + (j + 0.5) / kSub);
            f += formFactor(p.x, p.z);
          }
        }
        f /= kSub * kSub;
        for (int c = 0; c < 3; ++c) out[(size_t(py) * s.camera.width + px) * 3 + size_t(c)] = float(rho[c] * le[c] * f);
      }
    }
    return out;
  }
};

}  // namespace

TEST(ReferenceSurfaces, EmissiveSquareLightsDiffuseGroundAsItsFormFactorSays) {
  LitGround g;
  ASSERT_NEAR(g.formFactor(0, 0), 4.0 * cornerFormFactor(0.5, 0.5), 1e-15);
  ASSERT_NEAR(cornerFormFactor(1e9, 1e9), 0.25, 1e-8);  // a quarter of the sky
  const std::vector<float> exact = g.exact();
  const struct {
    ref::EmitterStrategy strategy;
    const char* label;
    int spp;
  } cases[] = {{ref::EmitterStrategy::Mis, "mis", 4096},
               {ref::EmitterStrategy::LightSamplingOnly, "light_only", 4096},
               {ref::EmitterStrategy::DirectionSamplingOnly, "direction_only", 16384}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.label);
    g.scene.render.spp = c.spp;
    const Image img = render(g.scene, noMedium(), c.strategy);
    test::expectMatchesExact(img, exact, c.label, checkOptions());
    // Sensitive: a 2% error in the light's pdf (its area, distance^2 or cosine) must fail.
    std::vector<float> off = exact;
    for (float& v : off) v *= 0.98f;
    EXPECT_FALSE(test::checkAgainstExact(img, off).aggregate.pass);
  }
}

TEST(ReferenceSurfaces, EmitterSamplingAndDirectionSamplingAgreeOnAGlossyConductor) {
  // No closed form: the three estimators of the same integral must agree with each other.
  LitGround g;
  g.scene.surfaces[0].material = SurfaceMaterial::Conductor;
  g.scene.surfaces[0].roughness = 0.3f;
  g.scene.surfaces[0].f0 = {0.9f, 0.6f, 0.3f};
  g.scene.camera.base.position = {1.2f, 0.3f, 0.1f};  // sees the emitter's glossy reflection
  g.scene.camera.base.lookAt = {0.6f, 0.0f, 0.0f};
  g.scene.camera.base.fovY = 40.0f;
  g.scene.render.spp = 8192;
  const Image mis = render(g.scene, noMedium(), ref::EmitterStrategy::Mis);
  const Image light = render(g.scene, noMedium(), ref::EmitterStrategy::LightSamplingOnly);
  const Image direction = render(g.scene, noMedium(), ref::EmitterStrategy::DirectionSamplingOnly);
  double sum = 0.0;
  for (float v : mis.rgb) sum += v;
  ASSERT_GT(sum, 0.0) << "the camera sees light reflected by the conductor";
  test::expectMatchesReference(light, direction, "light_vs_direction", checkOptions());
  test::expectMatchesReference(mis, light, "mis_vs_light", checkOptions());
  test::expectMatchesReference(mis, direction, "mis_vs_direction", checkOptions());
}

namespace {

// A dense box of smoke, voxels [0, 15] at 1/16 (world [0, 0.94]^3), over a ground at y = -1 lit by
// a sun along (-1, -1, 0): the box's shadow falls around x = -1, beside it. The camera looks
// straight down from above the shadow's edge.
struct SmokeOverGround {
  Scene scene = sceneLookingAt({-0.3f, 6.0f, 0.47f}, {-0.3f, -1.0f, 0.47f}, {0, 0, -1}, 40.0f, 32);
  openvdb::FloatGrid::ConstPtr grid = test::makeBoxGrid(16, 1.0 / 16);

  explicit SmokeOverGround(float groundAlbedo) {
    scene.media[0].densityScale = 8.0f;
    scene.media[0].albedo = glm::vec3(0.9f);
    scene.surfaces.push_back(plane({0, -1, 0}, {0, 1, 0}, {10, 10}, glm::vec3(groundAlbedo)));
    Light sun;
    sun.type = LightType::Sun;
    sun.toLight = glm::normalize(glm::vec3(1, 1, 0));
    sun.irradiance = glm::vec3(3.0f);
    scene.lights.push_back(sun);
    scene.render.maxBounces = 8;
    scene.render.spp = 64;
  }
};

}  // namespace

TEST(ReferenceSurfaces, SmokeShadowsTheGroundAndTheGroundLightsTheSmoke) {
  SmokeOverGround g(0.5f);
  const Image img = render(g.scene, g.grid);
  for (float v : img.rgb) ASSERT_TRUE(std::isfinite(v));
  // Pixels whose ground point lies in the box's core shadow (its sun ray crosses the box's middle
  // [0.2, 0.74]^3) and pixels in full sun well clear of it and of the box seen from above.
  double shadowSum = 0.0, sunSum = 0.0;
  int shadowCount = 0, sunCount = 0;
  for (int py = 0; py < img.height; ++py) {
    for (int px = 0; px < img.width; ++px) {
      const dvec3 q = groundPoint(g.scene, px + 0.5, py + 0.5, -1.0);
      // The sun ray from q reaches height y at x = q.x + (y + 1).
      const double xMid = q.x + (0.47 + 1.0);
      const double value = img.rgb[(size_t(py) * img.width + px) * 3];
      if (xMid > 0.2 && xMid < 0.74 && q.z > 0.2 && q.z < 0.74) {
        shadowSum += value;
        ++shadowCount;
      } else if ((xMid < -0.6 || q.z < -0.4 || q.z > 1.4) && (q.x < -0.2 || q.z < -0.2 || q.z > 1.2)) {
        sunSum += value;
        ++sunCount;
      }
    }
  }
  ASSERT_GT(shadowCount, 4);
  ASSERT_GT(sunCount, 20);
  const double shadow = shadowSum / shadowCount, sun = sunSum / sunCount;
  // In full sun: rho E cos(45 deg) / pi plus a little light from the smoke.
  EXPECT_GT(sun, 0.5 * 3.0 * std::sqrt(0.5) / M_PI * 0.99);
  EXPECT_LT(shadow, 0.5 * sun) << "shadow " << shadow << " sun " << sun;

  // The top of the smoke, seen through a narrow view that holds nothing else: over a black ground
  // it is darker, by more than the noise, since the ground no longer bounces sunlight into it.
  const auto topOfSmoke = [](float groundAlbedo) {
    SmokeOverGround t(groundAlbedo);
    t.scene.camera.base.position = {0.47f, 6.0f, 0.47f};
    t.scene.camera.base.lookAt = {0.47f, -1.0f, 0.47f};
    t.scene.camera.base.fovY = 6.0f;
    t.scene.camera.width = t.scene.camera.height = 16;
    t.scene.render.spp = 512;
    return render(t.scene, t.grid);
  };
  const Image bright = topOfSmoke(0.9f), dark = topOfSmoke(0.0f);
  double difference = 0.0, var = 0.0;
  for (size_t i = 0; i < bright.rgb.size(); i += 3) {
    difference += double(bright.rgb[i]) - dark.rgb[i];
    var += double(bright.var[i]) + dark.var[i];
  }
  EXPECT_GT(difference, 4.0 * std::sqrt(var)) << "difference " << difference << " standard error " << std::sqrt(var);
}

TEST(ReferenceSurfaces, EmitterSamplingAndPhaseSamplingAgreeInSmokeOverALamp) {
  // The emitter lights a thin box of smoke from below: at medium vertices the emitter is reached
  // by light sampling and by phase sampling (MIS with the HG pdf), through ratio tracking and
  // delta tracking respectively. The three estimators must agree.
  // Every pixel looks through the box's bulk (a grazing pixel reaches the emitter so rarely by
  // phase sampling that its few hits make the variance estimate, and the Z-test, unreliable).
  Scene s = sceneLookingAt({3.0f, 0.6f, 0.47f}, {0.47f, 0.47f, 0.47f}, {0, 1, 0}, 16.0f, 8);
  s.media[0].densityScale = 2.0f;
  s.media[0].albedo = glm::vec3(0.8f);
  s.media[0].g = 0.3f;
  s.surfaces.push_back(emitter({0.47f, -0.3f, 0.47f}, {0, 1, 0}, {1.2f, 1.2f}, glm::vec3(3.0f, 2.0f, 1.0f)));
  s.render.maxBounces = 4;
  s.render.spp = 8192;
  const openvdb::FloatGrid::ConstPtr grid = test::makeBoxGrid(16, 1.0 / 16);
  const Image mis = render(s, grid, ref::EmitterStrategy::Mis);
  const Image light = render(s, grid, ref::EmitterStrategy::LightSamplingOnly);
  s.render.spp = 32768;
  const Image phase = render(s, grid, ref::EmitterStrategy::DirectionSamplingOnly);
  double sum = 0.0;
  for (float v : mis.rgb) sum += v;
  ASSERT_GT(sum, 0.0);
  test::expectMatchesReference(light, phase, "smoke_light_vs_phase", checkOptions());
  test::expectMatchesReference(mis, light, "smoke_mis_vs_light", checkOptions());
  test::expectMatchesReference(mis, phase, "smoke_mis_vs_phase", checkOptions());
}

TEST(ReferenceSurfaces, ASceneWithoutSurfacesBuildsNoEmbreeScene) {
  SmokeOverGround g(0.5f);
  g.scene.render.spp = 1;
  ref::ReferenceStats stats;
  size_t before = geo::EmbreeScene::built();
  Image img = render(g.scene, g.grid, ref::EmitterStrategy::Mis, &stats);
  EXPECT_EQ(geo::EmbreeScene::built(), before + 1) << "the counter counts";
  EXPECT_EQ(stats.surfaceTriangles, 2u);
  EXPECT_EQ(img.meta["surface_triangles"], "2");

  g.scene.surfaces.clear();
  before = geo::EmbreeScene::built();
  img = render(g.scene, g.grid, ref::EmitterStrategy::Mis, &stats);
  EXPECT_EQ(geo::EmbreeScene::built(), before);
  EXPECT_EQ(stats.surfaceTriangles, 0u);
  EXPECT_EQ(img.meta.count("surface_triangles"), 0u);
}

TEST(ReferenceSurfaces, BundledSmokeOverGroundRendersFromTheCommandLine) {
  const std::string out = test::outputDir("reference_surfaces_cli") + "/ground.exr";
  const test::RunResult r = test::runPlume({"reference", test::sourcePath("volumes/smoke/smoke_ground.json"), "-o", out,
                                            "--frames", "12", "--width", "16", "--height", "16", "--spp", "2", "-q"});
  ASSERT_EQ(r.exitCode, 0) << r.output;
  Image img = readExr(out);
  EXPECT_EQ(img.meta["surface_triangles"], "2210");  // the plane's 2 and the sphere's 2208
  for (float v : img.rgb) ASSERT_TRUE(std::isfinite(v));
}
