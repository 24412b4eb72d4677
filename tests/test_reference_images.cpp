// Tier d foundations (DESIGN §7): the CPU reference against analytic images, each checked with
// a per-pixel Z-test and an aggregate z-test on the image mean (support/reference_check.h).
//  - White furnace: albedo 1, constant environment L, medium fully inside the view: every
//    pixel is L (energy conservation).
//  - Single scattering in a homogeneous box lit by a sun straight above: the reference matches
//    a numerical integration of the single-scattering equation over each pixel's footprint.
//  - The reference's variance image agrees with the spread between two independent seeds.
#include "reference/reference.h"
#include "shaders/shared/phase.h"
#include "support/grids.h"
#include "support/reference_check.h"
#include "support/scenes.h"
#include "support/test_support.h"

#include <glm/glm.hpp>
#include <gtest/gtest.h>

#include <cmath>

using namespace plume;
using glm::dvec3;

namespace {

Scene sceneLookingAt(glm::vec3 position, glm::vec3 lookAt, float fovY, int size) {
  Scene s;
  s.path = "test-scene";
  s.camera.base.position = position;
  s.camera.base.lookAt = lookAt;
  s.camera.base.up = {0, 1, 0};
  s.camera.base.fovY = fovY;
  s.camera.width = s.camera.height = size;
  s.media.push_back(Medium{});
  return s;
}

Image renderQuiet(const Scene& scene, openvdb::FloatGrid::ConstPtr grid) {
  ref::ReferenceOptions opt;
  opt.progress = false;
  return ref::renderReference(scene, grid, opt);
}

test::ReferenceCheckOptions checkOptions() {
  test::ReferenceCheckOptions options;
  options.outputGroup = "reference_images";
  return options;
}

}  // namespace

TEST(ReferenceImages, WhiteFurnaceIsUniform) {
  // A 32^3 box of density 1 (world [0, 1.94]), tau ~ 3 across, seen whole.
  auto grid = test::makeBoxGrid(32, 1.0 / 16);
  Scene s = sceneLookingAt({3.5f, 2.5f, 4.0f}, {1.0f, 1.0f, 1.0f}, 40.0f, 16);
  s.media[0].densityScale = 1.5f;
  s.media[0].albedo = glm::vec3(1.0f);
  s.media[0].g = 0.6f;
  Light env;
  env.type = LightType::Environment;
  env.radiance = {0.5f, 1.0f, 2.0f};
  s.lights.push_back(env);
  s.render.maxBounces = 100000;  // albedo 1: paths end by escaping
  s.render.spp = 256;
  Image img = renderQuiet(s, grid);
  std::vector<float> exact(img.rgb.size());
  for (size_t i = 0; i < exact.size(); ++i) exact[i] = env.radiance[int(i % 3)];
  test::expectMatchesExact(img, exact, "furnace", checkOptions());
  // The test is sensitive: a 2% energy loss must fail it.
  for (float& v : exact) v *= 0.98f;
  EXPECT_FALSE(test::checkAgainstExact(img, exact).aggregate.pass);
}

namespace {

// Index-space profile of one axis of a dense box of voxels [0, n-1] under trilinear
// interpolation: 0 outside (-1, n), ramps over one voxel, 1 inside.
double boxProfile(double x, int n) { return std::clamp(std::min(x + 1.0, double(n) - x), 0.0, 1.0); }
// Integral of the profile from y to +infinity.
double boxProfileTail(double y, int n) {
  if (y >= n) return 0.0;
  if (y >= n - 1) return 0.5 * (n - y) * (n - y);
  if (y >= 0) return (n - 1 - y) + 0.5;
  if (y >= -1) return n - 0.5 * (y + 1) * (y + 1);
  return n;
}

// Single scattering radiance along one camera ray through the box (sun straight above).
double singleScatter(dvec3 o, dvec3 d, int n, double vs, double scale, double albedo, float g, double E) {
  // The box's support in world space is [-vs, n*vs]^3; clip the ray to it.
  double t0 = 0, t1 = 1e30;
  for (int a = 0; a < 3; ++a) {
    double lo = -vs, hi = n * vs;
    if (std::abs(d[a]) < 1e-12) {
      if (o[a] < lo || o[a] > hi) return 0.0;
      continue;
    }
    double ta = (lo - o[a]) / d[a], tb = (hi - o[a]) / d[a];
    t0 = std::max(t0, std::min(ta, tb));
    t1 = std::min(t1, std::max(ta, tb));
  }
  if (t0 >= t1) return 0.0;
  const double cosTheta = d.y;  // dot(to_light = +y, ray direction)
  const double ph = shared::ph_hg(float(cosTheta), g);
  const int steps = 3000;
  const double dt = (t1 - t0) / steps;
  double tauCam = 0, L = 0;
  for (int i = 0; i < steps; ++i) {
    dvec3 x = (o + (t0 + (i + 0.5) * dt) * d) / vs;  // index space, midpoint rule
    double px = boxProfile(x.x, n), pz = boxProfile(x.z, n);
    double sigma = scale * px * boxProfile(x.y, n) * pz;
    double tauSun = scale * vs * px * pz * boxProfileTail(x.y, n);
    double tauMid = tauCam + 0.5 * sigma * dt;
    L += std::exp(-tauMid) * sigma * albedo * ph * E * std::exp(-tauSun) * dt;
    tauCam += sigma * dt;
  }
  return L;
}

}  // namespace

TEST(ReferenceImages, SingleScatteringBoxMatchesNumericalIntegration) {
  const int n = 24, size = 12;
  const double vs = 1.0 / 12, scale = 1.2, albedo = 0.8, E = 3.0;
  const float g = 0.3f;
  auto grid = test::makeBoxGrid(n, vs);
  Scene s = sceneLookingAt({2.6f, 1.6f, 4.2f}, {1.0f, 1.0f, 1.0f}, 36.0f, size);
  s.media[0].densityScale = float(scale);
  s.media[0].albedo = glm::vec3(float(albedo));
  s.media[0].g = g;
  Light sun;
  sun.type = LightType::Sun;
  sun.toLight = {0, 1, 0};
  sun.irradiance = glm::vec3(float(E));
  s.lights.push_back(sun);
  s.render.maxBounces = 1;
  s.render.spp = 1024;
  Image img = renderQuiet(s, grid);

  // The same camera model as the reference (DESIGN §2), integrated over each pixel's square.
  const CameraPose& pose = s.camera.base;
  dvec3 pos(pose.position), fwd = glm::normalize(dvec3(pose.lookAt - pose.position));
  dvec3 right = glm::normalize(glm::cross(fwd, dvec3(pose.up))), up = glm::cross(right, fwd);
  const double tanHalf = std::tan(glm::radians(double(pose.fovY)) / 2);
  std::vector<float> exact(3 * size * size);
  const int sub = 8;
  for (int py = 0; py < size; ++py)
    for (int px = 0; px < size; ++px) {
      double sum = 0;
      for (int j = 0; j < sub; ++j)
        for (int i = 0; i < sub; ++i) {
          double sx = (2.0 * (px + (i + 0.5) / sub) / size - 1.0) * tanHalf;
          double sy = (1.0 - 2.0 * (py + (j + 0.5) / sub) / size) * tanHalf;
          sum += singleScatter(pos, glm::normalize(fwd + sx * right + sy * up), n, vs, scale, albedo, g, E);
        }
      for (int c = 0; c < 3; ++c) exact[3 * (py * size + px) + c] = float(sum / (sub * sub));
    }
  test::expectMatchesExact(img, exact, "single_scatter", checkOptions());
  // Sensitivity: a 2% error in the sun's strength must fail.
  std::vector<float> wrong = exact;
  for (float& v : wrong) v *= 1.02f;
  EXPECT_FALSE(test::checkAgainstExact(img, wrong).aggregate.pass);
}

TEST(ReferenceImages, VarianceImageMatchesSpreadBetweenSeeds) {
  auto grid = test::makeNoiseGrid(48, 1.0 / 24);
  Scene s = sceneLookingAt({1.0f, 1.3f, 4.0f}, {1.0f, 1.0f, 1.0f}, 35.0f, 32);
  s.media[0].densityScale = 6.0f;
  s.media[0].albedo = glm::vec3(0.9f);
  s.media[0].g = 0.3f;
  s.lights = {test::sunLight({0.5f, 1.0f, 0.3f}, glm::vec3(3.0f)), test::skyLight({0.1f, 0.12f, 0.15f})};
  s.render.maxBounces = 8;
  s.render.spp = 64;
  s.render.seed = 1;
  Image a = renderQuiet(s, grid);
  s.render.seed = 2;
  Image b = renderQuiet(s, grid);
  // E[(a - b)^2] = var(a) + var(b): compare the sums over all pixels and channels.
  double spread = 0, predicted = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i) {
    spread += double(a.rgb[i] - b.rgb[i]) * (a.rgb[i] - b.rgb[i]);
    predicted += a.var[i] + b.var[i];
  }
  ASSERT_GT(predicted, 0);
  EXPECT_NEAR(spread / predicted, 1.0, 0.1) << "spread " << spread << " predicted " << predicted;
  // And the two seeds agree with each other.
  test::expectMatchesReference(a, b, "seeds", checkOptions());
  // Same seed, same image (determinism independent of threading).
  s.render.seed = 2;
  EXPECT_EQ(renderQuiet(s, grid).rgb, b.rgb);
}
