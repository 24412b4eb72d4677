// Environment maps on the CPU (DESIGN §2, §7 tier a): the shared sampler (shaders/shared/envmap.h,
// data from render/gpu_envmap.cpp) against its own pdf by a chi-square test on a map with a tiny
// bright sun and a dim sky; its pdf integrates to 1; the orientation convention (`up`,
// `rotate_y_deg`, u = atan2(x, -z) / 2pi, v = acos(y) / pi) on directions worked out by hand,
// for both the shared code and the CPU reference's own (reference/environment.cpp); loading
// zeroes and counts bad texels; and in the CPU reference a constant map renders as the constant
// environment light.
#include "core/error.h"
#include "io/environment_map.h"
#include "io/image.h"
#include "reference/environment.h"
#include "reference/reference.h"
#include "render/gpu_envmap.h"
#include "shaders/shared/envmap.h"
#include "shaders/shared/rng.h"
#include "support/grids.h"
#include "support/reference_check.h"
#include "support/scenes.h"
#include "support/test_support.h"

#include <gtest/gtest.h>
#include <glm/glm.hpp>

#include <cmath>
#include <filesystem>
#include <limits>

using namespace plume;
namespace sh = plume::shared;

namespace {

// A W x H map: a dim sky (a smooth gradient, dimmer below the horizon) and one texel (sunCol,
// sunRow) `sunGain` times brighter than the sky's brightest.
EnvironmentMapImage sunAndSky(int W, int H, int sunCol, int sunRow, float sunGain) {
  EnvironmentMapImage m;
  m.width = W;
  m.height = H;
  m.texels.resize(size_t(W) * H);
  for (int r = 0; r < H; ++r) {
    for (int c = 0; c < W; ++c) {
      const float v = (r + 0.5f) / H, u = (c + 0.5f) / W;
      glm::vec3 L = v < 0.5f ? glm::vec3(0.05f, 0.07f, 0.12f) * (1.5f - v) : glm::vec3(0.02f, 0.018f, 0.015f);
      L *= 1.0f + 0.3f * std::sin(6.2831853f * u);
      m.texels[size_t(r) * W + c] = L;
    }
  }
  m.texels[size_t(sunRow) * W + sunCol] = glm::vec3(sunGain * 0.2f);
  return m;
}

// The local direction of (u, v) by DESIGN §2, written out again here.
glm::dvec3 designLocal(double u, double v) {
  const double theta = M_PI * v, phi = 2.0 * M_PI * u;
  return {std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi)};
}

std::string writeMap(const EnvironmentMapImage& m, const std::string& name) {
  Image im(m.width, m.height);
  for (int y = 0; y < m.height; ++y)
    for (int x = 0; x < m.width; ++x) im.setPixel(x, y, m.texels[size_t(y) * m.width + x]);
  const std::string path = (std::filesystem::path(test::outputDir("envmap_maps")) / name).string();
  writeExr(path, im);
  return path;
}

}  // namespace

// Chi-square of env_sample's directions against env_pdf, in bins of a quarter texel in (u, v)
// of the map's local frame (up and rotation not trivial): the expected count of a bin is
// N * pdf * sin(theta) * dtheta * dphi at its centre (pdf * sin(theta) is constant over a texel),
// so the test checks the texel probabilities, the uniform placement within a texel and the pdf's
// W H / (2 pi^2 sin theta) at once.
TEST(EnvMap, SamplingMatchesPdfChiSquare) {
  const int W = 32, H = 16;
  const EnvironmentMapImage image = sunAndSky(W, H, 21, 4, 2000.0f);
  const EnvMapData d = buildEnvMapData(image, 1.5f, glm::vec3(0.2f, 0.3f, 1.0f), 37.0f);
  const float* data = d.data.data();
  const int S = 2;  // sub-bins per texel and axis
  const int BW = W * S, BH = H * S;
  std::vector<double> observed(size_t(BW) * BH, 0.0), expected(observed.size(), 0.0);
  const int n = 2000000;
  sh::RngState rng = sh::rng_init(glm::uvec2(3, 4), 5u, sh::RNG_STREAM_TEST, 6u);
  for (int i = 0; i < n; ++i) {
    const glm::vec3 w = sh::env_sample(data, d.header, sh::rng_float2(rng));
    ASSERT_NEAR(glm::length(w), 1.0f, 1e-4f);
    const glm::vec2 uv = sh::env_local_uv(sh::env_to_local(d.header, w));
    const int bx = std::min(BW - 1, int(uv.x * BW)), by = std::min(BH - 1, int(uv.y * BH));
    observed[size_t(by) * BW + bx] += 1.0;
  }
  for (int by = 0; by < BH; ++by) {
    for (int bx = 0; bx < BW; ++bx) {
      const glm::dvec3 local = designLocal((bx + 0.5) / BW, (by + 0.5) / BH);
      const glm::vec3 world = sh::env_to_world(d.header, glm::vec3(local));
      const double sinTheta = std::sin(M_PI * (by + 0.5) / BH);
      expected[size_t(by) * BW + bx] = n * double(sh::env_pdf(data, d.header, world)) * sinTheta * (M_PI / BH) * (2.0 * M_PI / BW);
    }
  }
  // The sun's texel takes a large share (it must, for the test to mean something).
  const glm::dvec3 sunDir = designLocal((21 + 0.5) / W, (4 + 0.5) / H);
  const double sunP = sh::env_texel_probability(data, d.header, glm::uvec2(21, 4));
  EXPECT_GT(sunP, 0.5);
  EXPECT_GT(sh::env_pdf(data, d.header, sh::env_to_world(d.header, glm::vec3(sunDir))), 100.0f / (4.0f * float(M_PI)));
  test::expectChi2(observed, expected, "envmap_chi2", "env_sample against env_pdf");
}

// The pdf integrates to 1 over the sphere: a midpoint rule on 4 x 4 points per texel in (u, v),
// each point taken to world space and looked up again (the world/local round trip included),
// d omega = 2 pi^2 sin(theta) du dv. And a black map samples without dividing by zero.
TEST(EnvMap, PdfIntegratesToOne) {
  const int W = 64, H = 32;
  for (float rot : {0.0f, -75.0f}) {
    const EnvMapData d = buildEnvMapData(sunAndSky(W, H, 5, 20, 5000.0f), 1.0f, glm::vec3(0, -1, 0.001f), rot);
    const int S = 4;
    double sum = 0.0;
    for (int y = 0; y < H * S; ++y) {
      for (int x = 0; x < W * S; ++x) {
        const double u = (x + 0.5) / (W * S), v = (y + 0.5) / (H * S);
        const glm::vec3 w = sh::env_to_world(d.header, glm::vec3(designLocal(u, v)));
        sum += double(sh::env_pdf(d.data.data(), d.header, glm::normalize(w))) * 2.0 * M_PI * M_PI * std::sin(M_PI * v) /
               (double(W * S) * H * S);
      }
    }
    EXPECT_NEAR(sum, 1.0, 1e-4) << "rotate_y_deg " << rot;
  }
  EnvironmentMapImage black = sunAndSky(W, H, 0, 0, 1.0f);
  for (glm::vec3& t : black.texels) t = glm::vec3(0.0f);
  const EnvMapData d = buildEnvMapData(black, 1.0f, glm::vec3(0, 1, 0), 0.0f);
  sh::RngState rng = sh::rng_init(glm::uvec2(1, 1), 1u, sh::RNG_STREAM_TEST, 1u);
  for (int i = 0; i < 1000; ++i) {
    const glm::vec3 w = sh::env_sample(d.data.data(), d.header, sh::rng_float2(rng));
    const float pdf = sh::env_pdf(d.data.data(), d.header, w);
    ASSERT_TRUE(std::isfinite(w.x) && std::isfinite(w.y) && std::isfinite(w.z));
    ASSERT_TRUE(std::isfinite(pdf) && pdf > 0.0f);
    ASSERT_EQ(sh::env_radiance(d.data.data(), d.header, w), glm::vec3(0.0f));
  }
}

// DESIGN §2 worked by hand. With up = +Z (Blender) M maps (x, y, z) to (x, z, -y); R_y(-90 deg)
// then maps (x, y, z) to (-z, y, x): a world direction (x, y, z) reads the map at local
// (y, z, x). The texel at u = 0.25, v = 0.25 looks along local (sin 45, cos 45, 0), so world
// (0, 0.7071, 0.7071). With up = -Y (a half turn about X) and no rotation, local (x, y, z) is
// world (x, -y, -z): the same texel is seen from world (0.7071, -0.7071, 0). With the defaults
// the texel at u = 0 (column 0's left edge) and v = 0.5 looks along -Z.
TEST(EnvMap, OrientationFollowsDesign) {
  const int W = 64, H = 32;
  const int col = W / 4, row = H / 4;  // the texel whose corner is (u, v) = (0.25, 0.25)
  EnvironmentMapImage image = sunAndSky(W, H, col, row, 1e4f);
  struct Case {
    glm::vec3 up;
    float rot;
    glm::dvec3 world;  // where the texel's corner (0.25, 0.25) is seen from
  } cases[] = {
      {{0, 0, 1}, 90.0f, glm::normalize(glm::dvec3(0, 1, 1))},
      {{0, -1, 0}, 0.0f, glm::normalize(glm::dvec3(1, -1, 0))},
      {{0, 1, 0}, 0.0f, glm::normalize(glm::dvec3(1, 1, 0))},
      {{0, 1, 0}, 90.0f, glm::normalize(glm::dvec3(0, 1, -1))},  // R_y(-90): local (-z, y, x)
  };
  const std::string path = writeMap(image, "orientation.exr");
  const float sun = image.texels[size_t(row) * W + col].x;
  for (const Case& c : cases) {
    SCOPED_TRACE(testing::Message() << "up " << c.up.x << " " << c.up.y << " " << c.up.z << ", rotate_y_deg " << c.rot);
    const EnvMapData d = buildEnvMapData(image, 1.0f, c.up, c.rot);
    Light light = test::skyLight(glm::vec3(0));
    light.map = path;
    light.up = c.up;
    light.rotateYDeg = c.rot;
    ref::ReferenceEnvironmentMap refMap(light, "test: lights[0].map");
    // Just inside the texel (its corner nudged towards its centre) reads the bright texel; just
    // outside, towards the neighbours, reads sky.
    const glm::dmat3 toLocal = envMapWorldToLocal(c.up, c.rot);
    const glm::dvec3 local = toLocal * c.world;
    EXPECT_NEAR(local.x, designLocal(0.25, 0.25).x, 1e-5);
    EXPECT_NEAR(local.y, designLocal(0.25, 0.25).y, 1e-5);
    EXPECT_NEAR(local.z, designLocal(0.25, 0.25).z, 1e-5);
    const glm::dvec3 inside = glm::transpose(toLocal) * designLocal(0.25 + 0.2 / W, 0.25 + 0.2 / H);
    const glm::dvec3 outside = glm::transpose(toLocal) * designLocal(0.25 - 0.2 / W, 0.25 - 0.2 / H);
    EXPECT_EQ(sh::env_radiance(d.data.data(), d.header, glm::vec3(inside)).x, sun);
    EXPECT_LT(sh::env_radiance(d.data.data(), d.header, glm::vec3(outside)).x, 1.0f);
    EXPECT_EQ(float(refMap.radiance(inside).x), sun);
    EXPECT_LT(refMap.radiance(outside).x, 1.0);
    // Both samplers send most samples towards the texel: within its angular size of c.world.
    sh::RngState rng = sh::rng_init(glm::uvec2(7, 7), 1u, sh::RNG_STREAM_TEST, 2u);
    int near = 0, refNear = 0;
    for (int i = 0; i < 2000; ++i) {
      const glm::vec2 u = sh::rng_float2(rng);
      near += glm::dot(glm::dvec3(sh::env_sample(d.data.data(), d.header, u)), c.world) > std::cos(0.15);
      double pdf;
      refNear += glm::dot(refMap.sample(u.x, u.y, sh::rng_float(rng), pdf), c.world) > std::cos(0.15);
    }
    EXPECT_GT(near, 1600);
    EXPECT_GT(refNear, 1600);
  }
  // Column 0 looks along local -Z, the default world -Z: u = 0 at its left edge, v = 0.5.
  const EnvMapData d = buildEnvMapData(image, 1.0f, glm::vec3(0, 1, 0), 0.0f);
  const glm::vec2 uv = sh::env_local_uv(sh::env_to_local(d.header, glm::vec3(0, 0, -1)));
  EXPECT_NEAR(uv.x, 0.0f, 1e-6f);
  EXPECT_NEAR(uv.y, 0.5f, 1e-6f);
  // +X is a quarter turn on (u = 0.25), +Z half (0.5), and +Y the top row (v = 0).
  EXPECT_NEAR(sh::env_local_uv(glm::vec3(1, 0, 0)).x, 0.25f, 1e-6f);
  EXPECT_NEAR(sh::env_local_uv(glm::vec3(0, 0, 1)).x, 0.5f, 1e-6f);
  EXPECT_NEAR(sh::env_local_uv(glm::vec3(0, 1, 0)).y, 0.0f, 1e-6f);
}

// Loading: NaN, Inf and negative texels are zeroed and counted; the others kept as read.
TEST(EnvMap, LoadingZeroesAndCountsBadTexels) {
  EnvironmentMapImage image = sunAndSky(8, 4, 1, 1, 10.0f);
  image.texels[3].y = std::numeric_limits<float>::quiet_NaN();
  image.texels[9] = glm::vec3(std::numeric_limits<float>::infinity());
  image.texels[17].z = -2.0f;
  const std::string path = writeMap(image, "bad_texels.exr");
  const EnvironmentMapImage loaded = loadEnvironmentMap(path, "test: lights[0].map");
  EXPECT_EQ(loaded.zeroedTexels, 3u);
  EXPECT_EQ(loaded.texels[3].y, 0.0f);
  EXPECT_EQ(loaded.texels[3].x, image.texels[3].x);
  EXPECT_EQ(loaded.texels[9], glm::vec3(0.0f));
  EXPECT_EQ(loaded.texels[17].z, 0.0f);
  EXPECT_EQ(loaded.texels[5], image.texels[5]);
  EnvironmentMapLimit limit;
  limit.maxTexels = 31;
  limit.what = "a test limit";
  try {
    loadEnvironmentMap(path, "test: lights[0].map", limit);
    ADD_FAILURE() << "a map over the limit loaded";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("a test limit"), std::string::npos) << e.what();
  }
}

// The CPU reference: a constant map (map sampling, MIS-free) renders as the constant environment
// light (phase sampling) within their noise, on a small cloud with multiple scattering.
TEST(EnvMap, ReferenceConstantMapEqualsConstantEnvironment) {
  const glm::vec3 L(0.3f, 0.4f, 0.5f);
  EnvironmentMapImage image = sunAndSky(16, 8, 0, 0, 1.0f);
  for (glm::vec3& t : image.texels) t = L * 0.5f;
  const std::string path = writeMap(image, "constant.exr");
  Scene s;
  s.path = "test-scene";
  s.camera.base.position = {1.0f, 1.2f, 4.0f};
  s.camera.base.lookAt = {1.0f, 1.0f, 1.0f};
  s.camera.width = s.camera.height = 12;
  Medium m;
  m.densityScale = 4.0f;
  m.albedo = glm::vec3(0.9f);
  m.g = 0.5f;
  s.media.push_back(m);
  s.render.maxBounces = 3;
  s.render.spp = 2048;
  Scene sMap = s;
  s.lights = {test::skyLight(L)};
  Light mapLight = test::skyLight(glm::vec3(0));
  mapLight.map = path;
  mapLight.scale = 2.0f;  // texels L / 2 times scale 2
  mapLight.rotateYDeg = 33.0f;
  sMap.lights = {mapLight};
  auto grid = test::makeNoiseGrid(40, 1.0 / 20, 4);
  ref::ReferenceOptions opt;
  opt.progress = false;
  const Image constant = ref::renderReference(s, grid, opt);
  sMap.render.seed = 99;
  const Image mapped = ref::renderReference(sMap, grid, opt);
  test::ReferenceCheckOptions options;
  options.outputGroup = "envmap";
  test::expectMatchesReference(mapped, constant, "reference_constant_map", options);
}
