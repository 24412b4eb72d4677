// The many-lights scene (issue 12 deliverable 6; volumes/city/): `plume-volgen city` writes the
// requested number of emissive quads, deterministically, and refuses bad arguments; the bundled
// OBJ files are its default output; the emitters' alias table chooses among thousands of
// triangles in proportion to power with the shader's own arithmetic; and the GPU path tracer on the
// bundled city (a small image, the real OBJ files, 8000 emissive triangles) matches the CPU
// reference (per-pixel and aggregate Z-tests).
#include "core/log.h"
#include "geometry/obj.h"
#include "geometry/scene_mesh.h"
#include "media/bake.h"
#include "media/vdb_loader.h"
#include "render/gpu_surfaces.h"
#include "render/gpu_volume.h"
#include "render/restir.h"
#include "shaders/shared/rng.h"
#include "support/gpu_fixture.h"
#include "support/light_tree.h"
#include "support/restir_check.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>

using namespace plume;
namespace fs = std::filesystem;

namespace {

const char* const kCityFiles[] = {"city_buildings.obj", "city_lamps.obj", "city_windows_warm.obj",
                                  "city_windows_cool.obj"};

test::RunResult runVolgen(const std::vector<std::string>& args) {
  std::string cmd = PLUME_VOLGEN;
  for (const std::string& a : args) cmd += " '" + a + "'";
  cmd += " 2>&1";
  test::RunResult r;
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return r;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, pipe)) > 0) r.output.append(buf, n);
  const int status = pclose(pipe);
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

std::string readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Faces ("f" lines) and the vertices of each.
std::vector<int> faceSizes(const fs::path& p) {
  std::ifstream in(p);
  std::vector<int> sizes;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("f ", 0) != 0) continue;
    std::istringstream s(line.substr(2));
    int n = 0;
    for (std::string v; s >> v;) ++n;
    sizes.push_back(n);
  }
  return sizes;
}

glm::vec3 triangleNormal(const geo::TriangleMesh& m, size_t i) {
  const glm::uvec3 t = m.triangles[i];
  return glm::normalize(glm::cross(m.positions[t.y] - m.positions[t.x], m.positions[t.z] - m.positions[t.x]));
}

}  // namespace

// The same arguments write the same bytes; the emissive files hold exactly --quads quads, a
// --lamp-share of them lamps facing down, the windows facing sideways; another seed differs.
TEST(CityGenerator, WritesTheRequestedQuadsDeterministically) {
  const std::string dir = test::outputDir("city");
  const std::vector<std::string> args = {"city", "--quads", "600", "--seed", "5", "--radius", "2"};
  auto with = [&](std::vector<std::string> a, const std::string& out) {
    a.insert(a.end(), {"--out", out});
    return a;
  };
  for (const char* sub : {"a", "b"}) {
    const test::RunResult r = runVolgen(with(args, dir + "/" + sub));
    ASSERT_EQ(r.exitCode, 0) << r.output;
  }
  std::vector<std::string> seed6 = args;
  seed6[4] = "6";
  ASSERT_EQ(runVolgen(with(seed6, dir + "/c")).exitCode, 0);
  int emissive = 0, differ = 0;
  for (const char* f : kCityFiles) {
    const std::string a = readFile(fs::path(dir) / "a" / f);
    ASSERT_FALSE(a.empty()) << f;
    EXPECT_EQ(a, readFile(fs::path(dir) / "b" / f)) << f;
    differ += a != readFile(fs::path(dir) / "c" / f);
    const std::vector<int> sizes = faceSizes(fs::path(dir) / "a" / f);
    for (int n : sizes) EXPECT_EQ(n, 4) << f;
    if (std::string(f) != "city_buildings.obj") emissive += int(sizes.size());
  }
  EXPECT_EQ(emissive, 600);
  EXPECT_EQ(differ, 4);
  EXPECT_EQ(faceSizes(fs::path(dir) / "a" / "city_lamps.obj").size(), 150u);  // the default lamp share 0.25
  // Orientation (DESIGN §2, counter-clockwise = front): lamps face down, windows sideways, walls
  // and roofs out of their box (never down).
  const geo::TriangleMesh lamps = geo::loadObj(dir + "/a/city_lamps.obj").mesh;
  ASSERT_EQ(lamps.triangleCount(), 300u);
  for (size_t i = 0; i < lamps.triangleCount(); ++i) ASSERT_NEAR(triangleNormal(lamps, i).y, -1.0f, 1e-5f) << i;
  for (const char* f : {"city_windows_warm.obj", "city_windows_cool.obj"}) {
    const geo::TriangleMesh w = geo::loadObj(dir + "/a/" + f).mesh;
    for (size_t i = 0; i < w.triangleCount(); ++i) ASSERT_NEAR(triangleNormal(w, i).y, 0.0f, 1e-5f) << f << " " << i;
  }
  const geo::TriangleMesh b = geo::loadObj(dir + "/a/city_buildings.obj").mesh;
  for (size_t i = 0; i < b.triangleCount(); ++i) ASSERT_GT(triangleNormal(b, i).y, -0.5f) << i;
}

// volumes/city/*.obj are what `plume-volgen city` writes with its defaults (volumes/README.md).
TEST(CityGenerator, BundledFilesAreItsDefaultOutput) {
  const std::string dir = test::outputDir("city");
  const test::RunResult r = runVolgen({"city", "--out", dir});
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("4000 emissive quads"), std::string::npos) << r.output;
  for (const char* f : kCityFiles)
    EXPECT_TRUE(readFile(fs::path(dir) / f) == readFile(test::sourcePath(std::string("volumes/city/") + f))) << f;
}

// Bad arguments: a non-zero exit, a message naming the option, and no file written.
TEST(CityGenerator, RefusesBadArguments) {
  const std::string dir = test::outputDir("city");
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--quads", "0"}, "--quads"},
      {{"--quads", "900000"}, "lower --quads"},
      {{"--lamp-share", "1.5"}, "--lamp-share"},
      {{"--street", "0.2", "--block", "0.3"}, "--street"},
      {{"--radius", "0.5"}, "--radius"},
      {{"--max-height", "nan"}, "--max-height"},
  };
  for (const auto& [args, message] : cases) {
    std::vector<std::string> a = {"city", "--out", dir + "/out"};
    a.insert(a.end(), args.begin(), args.end());
    const test::RunResult r = runVolgen(a);
    EXPECT_NE(r.exitCode, 0) << args[0];
    EXPECT_NE(r.output.find(message), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir + "/out")) << args[0];
  }
}

// The light tree over the bundled city's 8000 emissive triangles, descended as the shaders do
// (lt_sample with one number from the shader's RNG, rescaled at each level): at shading points in
// the smoke, on the ground under a street lamp, in a street and high above the city, 4 million
// samples each against the probabilities lt_pmf gives every triangle and the rest, the chance of
// no sample (chi-square, Šidák over 4). The tree is that many times better than a choice by power alone where a lamp is
// near: the test prints the probability of the nearest lamp's two triangles under each scheme,
// and requires the tree's to stay above 0.07 at the point under it.
// (With every inner node's first-child probability computed 10% high in lt_pmf only, by hand, it
// fails.)
TEST(CityEmitters, LightTreeSamplesThousandsOfEmittersAsItsProbabilitiesSay) {
  const Scene city = loadScene(test::sourcePath("volumes/city/city.json"));
  const geo::SceneMesh sm = geo::loadSceneSurfaces(city);
  std::vector<LightTreeEmitter> emitters;
  double total = 0.0;
  for (size_t i = 0; i < sm.mesh.triangleCount(); ++i) {
    const glm::vec3 le = city.surfaces[sm.triangleSurface[i]].emission;
    const double p = 0.5 * geo::doubleArea(sm.mesh, i) * (double(le.x) + double(le.y) + double(le.z)) / 3.0;
    const glm::uvec3 v = sm.mesh.triangles[i];
    if (p > 0.0) emitters.push_back({sm.mesh.positions[v.x], sm.mesh.positions[v.y], sm.mesh.positions[v.z], p, uint32_t(i)});
    total += p;
  }
  ASSERT_EQ(emitters.size(), 8000u);
  const LightTree tree = buildLightTree(emitters);
  EXPECT_EQ(tree.depth, 16);  // the SAOH build (a balanced tree: 13)
  test::ltTestNodes = &tree.nodes;
  // A street lamp's centre, 0.05 above the street and facing down: the point below it.
  const LightTreeEmitter& lamp = *std::find_if(emitters.begin(), emitters.end(), [&](const LightTreeEmitter& e) {
    return glm::cross(e.v1 - e.v0, e.v2 - e.v0).y < 0.0f;
  });
  const glm::vec3 underLamp = (lamp.v0 + lamp.v1 + lamp.v2) / 3.0f - glm::vec3(0.0f, 0.04f, 0.0f);
  // Points in the smoke and above the city (no receiver), and on the ground under the lamp and in
  // a street (the ground's normal): the receiver bound of surface points is sampled too.
  const glm::vec3 up(0.0f, 1.0f, 0.0f);
  const std::vector<std::pair<glm::vec3, glm::vec3>> points = {
      {{0.0f, 0.5f, 0.0f}, glm::vec3(0.0f)}, {underLamp, up}, {{1.9f, 0.01f, 0.35f}, up}, {{0.3f, 6.0f, -0.2f}, glm::vec3(0.0f)}};
  uint32_t stream = 0;
  for (const auto& [x, r] : points) {
    // One bin per emitter, and one for "no sample" (the descent reached a node none of whose
    // emitters faces x), whose probability is what the emitters' leave.
    const size_t none = emitters.size();
    std::map<uint32_t, size_t> index;
    std::vector<double> expected(none + 1), observed(none + 1, 0.0);
    double sum = 0.0;
    for (size_t i = 0; i < none; ++i) {
      index[emitters[i].triangle] = i;
      expected[i] = shared::lt_pmf(x, r, tree.trails[i]);
      sum += expected[i];
    }
    EXPECT_LE(sum, 1.0 + 1e-4);
    expected[none] = std::max(0.0, 1.0 - sum);
    std::printf("light tree at (%g, %g, %g): no sample with probability %.4f\n", x.x, x.y, x.z, expected[none]);
    constexpr int kSamples = 4'000'000;
    shared::RngState rng = shared::rng_init(shared::uvec2(7u, stream++), 0u, shared::RNG_STREAM_TEST, 3u);
    for (int s = 0; s < kSamples; ++s) {
      float pmf = 0.0f;
      const uint32_t tri = shared::lt_sample(x, r, shared::rng_to_float(shared::rng_next4(rng).x), pmf);
      observed[pmf > 0.0f ? index.at(tri) : none] += 1.0;
    }
    for (double& e : expected) e *= kSamples;
    test::expectChi2(observed, expected, "city", strf("light tree at (%g, %g, %g)", x.x, x.y, x.z), 4);
    if (x == underLamp) {
      const size_t i = size_t(&lamp - emitters.data());
      std::printf("under a street lamp: its triangle has probability %.3g by the tree, %.3g by power\n",
                  expected[i] / kSamples, lamp.power / total);
      EXPECT_GT(expected[i] / kSamples, 100.0 * lamp.power / total);
      // The distance term's mean over a node's sphere (shared/light_tree.h) gave 0.040 (0.019 with
      // the distance clamped at the radius); the descent's two-level steps, which weigh
      // grandchildren, 0.088.
      EXPECT_GT(expected[i] / kSamples, 0.07);
    }
  }
}

class CityGpuTest : public test::GpuTest {};

namespace {

// A 20 x 20 crop of the bundled city around the smoke's base, 3 bounces, and frame 24's grid
// (optical depth clamped as the renderers do).
Scene cityCrop() {
  Scene s = loadScene(test::sourcePath("volumes/city/city.json"));
  s.camera.width = s.camera.height = 20;
  s.camera.base.fovY = 16.0f;
  s.camera.base.lookAt = {0.0f, 0.3f, 0.0f};
  s.render.maxBounces = 3;
  return s;
}

LoadedGrid cityGrid(const Scene& s) {
  LoadedGrid grid = loadFloatGrid(s.medium().vdbPath(24), s.medium().densityGrid);
  clampOpticalDepth(*grid.grid, s.medium().densityScale);
  return grid;
}

}  // namespace

// The path tracer on the bundled city (the real OBJ files: 8000 emissive triangles, no other
// light) against the CPU reference: a 20 x 20 crop around the smoke's lit base, the plaza and the
// streets behind it, 3 bounces (smoke, ground, buildings), frame 24's grid. The path tracer picks
// lamps from the light tree; the reference by power alone, so it rarely finds the lamp that
// lights a patch of ground from close by and needs many samples: at 2048 spp pixel (9, 17) read
// 0.019 where 32768 spp give 0.067 (the path tracer: 0.060), and failed the test (z 5.3). Both
// estimators have rare large contributions in a few pixels (pixel (9, 4): the path tracer at
// 1024 spp read 0.27 with a variance that had not seen them, at 8192 spp 0.39, the reference at
// 32768 spp 0.40), hence 4096 spp against 16384. The aggregate test resolves about 4%; the same
// comparison with the path tracer's image scaled by 0.8 must fail.
// (test_city_slow.cpp: the whole picture at 32 x 32, resolving about 2%.)
TEST_F(CityGpuTest, PathTracerMatchesReferenceOnTheBundledCity) {
  const Scene s = cityCrop();
  const LoadedGrid grid = cityGrid(s);
  const test::ReferenceCheck check =
      test::expectPtMatchesReference(ctx(), compiler(), s, grid.grid, 4096, 16384, "city", "city", "emitters", 0.8f);
  EXPECT_LT(check.aggregate.resolvableBias().x, 0.15) << "too few samples for the test to mean much";
}

// Unbiased ReSTIR (one spatial round, pairwise MIS; light samples resampled at every candidate
// vertex, RestirOptions::lightCandidates) on a crop of the city seen from above against the
// reference: the many-lights case of issue 12, 1024 runs against 16384 spp (heavy tails: above). With the
// light resampling's 1 / L factor miscounted as 1 / (L - 1) (at L = 8 every light sample's weight
// 14% high) it failed: mean ratio 1.09 / 1.10 / 1.11, aggregate z 6.8-11.6 (256 runs, 2048 spp).
TEST_F(CityGpuTest, RestirMatchesReferenceOnTheBundledCity) {
  Scene s = cityCrop();
  // From above: the street lamps face down and the windows are seen edge-on, so the crop's light
  // is what the lamps scatter (the pixels of lamps seen directly are final shading's, and would
  // dominate the aggregate test).
  s.camera.base.position = {0.4f, 4.0f, 0.9f};
  s.camera.base.lookAt = {0.0f, 0.3f, 0.0f};
  ASSERT_GT(RestirOptions{}.lightCandidates, 1) << "the test is meant for light resampling";
  const LoadedGrid grid = cityGrid(s);
  test::expectRestirMatchesReference(ctx(), compiler(), s, grid.grid, 1024, 16384, "city", {shared::RS_MIS_PAIRWISE});
}

namespace {
// The whole city at 40 x 40, 2 bounces (the lamp pass's tests).
Scene smallCity() {
  Scene s = loadScene(test::sourcePath("volumes/city/city.json"));
  s.camera.width = s.camera.height = 40;
  s.render.maxBounces = 2;
  return s;
}
}  // namespace

// ReSTIR's lamps seen directly are traced only in the pixels whose camera rays may meet an
// emitter's front (render/pixel_order.h emitterPixelMask, a pass of their own over them); every
// other pixel's lamp reservoir would be empty, so the frames equal those of every pixel tracing
// its 16 rays over the whole pixel (RestirOptions::lampTriangles and lampRects off in both: the
// pieces and the rectangles draw other rays, tested by PixelOrder.EveryRayThatMeetsAnEmittersFront-
// LiesOnOneOfItsPieces, PixelOrder.EveryPixelThatSeesAnEmittersFrontIsMarked and the lamps' Z-tests,
// test_restir_surfaces.cpp), bit for bit: the whole city at 40 x 40 (8000 emitters, some under a pixel wide),
// four frames with a still camera (the lamp reservoirs' history merged) and four moving (309 and
// 340 of 1600 pixels traced). Can it fail: with the mask's triangles shrunk to their centroids and
// no margin (a sabotage of emitterPixelMask: 262 and 268 pixels) 33 and 27 channels differ.
TEST_F(CityGpuTest, LampPassGivesTheFramesOfEveryPixelTracingItsLamps) {
  Scene s = smallCity();
  const LoadedGrid grid = cityGrid(s);
  const GpuVolumeResources volume(ctx(), bakeVolume(grid), s.medium().densityScale);
  Scene moving = s;
  CameraKey key;
  key.frame = 4;
  key.pose = s.camera.base;
  key.pose.position += glm::vec3(0.3f, 0.1f, 0.0f);
  moving.camera.keys.push_back(key);
  for (const Scene* scene : {&s, &moving}) {
    const char* name = scene == &s ? "still camera" : "moving camera";
    auto frames = [&](bool cull, uint32_t& lampPixels) {
      RestirOptions o;
      o.cullLampPixels = cull;
      o.lampTriangles = false;
      o.lampRects = false;
      Restir restir(ctx(), compiler(), *scene, o);
      restir.setVolumes(volume, volume);
      std::vector<Image> out;
      for (int f = 1; f <= 4; ++f) out.push_back(restir.renderFrame(f, 1));
      lampPixels = restir.lampPixels();
      return out;
    };
    uint32_t culledPixels = 0, allPixels = 0;
    const std::vector<Image> culled = frames(true, culledPixels), traced = frames(false, allPixels);
    size_t differ = 0, lit = 0;
    for (size_t f = 0; f < culled.size(); ++f) {
      for (size_t i = 0; i < culled[f].rgb.size(); ++i) {
        differ += std::memcmp(&culled[f].rgb[i], &traced[f].rgb[i], sizeof(float)) != 0 ? 1 : 0;
        lit += traced[f].rgb[i] > 0.0f ? 1 : 0;
      }
    }
    std::printf("[city] lamp pass, %s: %u of %u pixels traced; %zu of %zu channels differ\n", name, culledPixels,
                allPixels, differ, lit);
    EXPECT_EQ(allPixels, 40u * 40u) << name;
    EXPECT_GT(culledPixels, 0u) << name;
    EXPECT_LT(culledPixels, allPixels / 2) << name << ": the mask must leave most pixels out";
    EXPECT_EQ(differ, 0u) << name << ": the lamp pass must not change any pixel";
    EXPECT_GT(lit, culled.size() * culled[0].rgb.size() / 4) << name << ": too few lit channels";
  }
}

// The pieces of emitter projections that ReSTIR's lamp reservoirs draw their rays on (RestirOptions::
// lampTriangles, render/pixel_order.h emitterPixelTriangles) sit in the parameter buffer, which
// must fit the device's largest storage buffer (lavapipe: 128 MiB, a 1080p frame filled by an
// emitter would pass it); past that the pixels with the most pieces draw in their rectangles in a
// pass of their own (Restir::lampRectPixels, logged). With room for no piece every pixel does, and
// the frames are those of the rectangles asked for (lampTriangles off), bit for bit; with room for
// some, some do. The city at 40 x 40, frames 1-2 of a still camera.
TEST_F(CityGpuTest, LampPiecesPastTheBufferLimitDrawInTheirRectangles) {
  const Scene s = smallCity();
  const LoadedGrid grid = cityGrid(s);
  const GpuVolumeResources volume(ctx(), bakeVolume(grid), s.medium().densityScale);
  struct Run {
    std::vector<Image> frames;
    uint32_t lampPixels = 0, rectPixels = 0;
  };
  auto run = [&](bool pieces, size_t words) {
    RestirOptions o;
    o.lampTriangles = pieces;
    o.lampPieceWords = words;
    Restir restir(ctx(), compiler(), s, o);
    restir.setVolumes(volume, volume);
    Run r;
    for (int f = 1; f <= 2; ++f) r.frames.push_back(restir.renderFrame(f, 1));
    r.lampPixels = restir.lampPixels();
    r.rectPixels = restir.lampRectPixels();
    return r;
  };
  auto differ = [](const Run& a, const Run& b) {
    size_t n = 0;
    for (size_t f = 0; f < a.frames.size(); ++f)
      for (size_t i = 0; i < a.frames[f].rgb.size(); ++i)
        n += std::memcmp(&a.frames[f].rgb[i], &b.frames[f].rgb[i], sizeof(float)) != 0 ? 1 : 0;
    return n;
  };
  const Run rects = run(false, 0), none = run(true, 1), some = run(true, 8 * 200), all = run(true, 0);
  std::printf("[city] lamp pieces: %u pixels may see an emitter; in rectangles: %u with room for no piece, %u with "
              "room for 200, %u with the device's; channels that differ from the rectangles' frames: %zu, %zu, %zu\n",
              all.lampPixels, none.rectPixels, some.rectPixels, all.rectPixels, differ(none, rects), differ(some, rects),
              differ(all, rects));
  EXPECT_EQ(rects.rectPixels, 0u) << "no pieces asked for, none refused";
  EXPECT_EQ(none.rectPixels, none.lampPixels);
  EXPECT_EQ(differ(none, rects), 0u) << "with no room for a piece the frames must be the rectangles'";
  EXPECT_GT(some.rectPixels, 0u);
  EXPECT_LT(some.rectPixels, some.lampPixels);
  EXPECT_GT(differ(some, rects), 0u);
  EXPECT_GT(differ(some, all), 0u);
  EXPECT_EQ(all.rectPixels, 0u) << "the city's pieces fit the device";
  EXPECT_GT(differ(all, rects), 0u);
}

// The bundled city on the device: 11922 triangles (the ground's 2, 392 boxes of 5 quads, 4000
// emissive quads), 8000 of them emitters; prints the BVH's figures (notes/city.md), with and
// without spatial splits.
TEST_F(CityGpuTest, SurfacesOnTheDevice) {
  const Scene s = loadScene(test::sourcePath("volumes/city/city.json"));
  const GpuSurfaces surfaces(ctx(), s);
  EXPECT_EQ(surfaces.emitterCount(), 8000u);
  const geo::BvhStats& st = surfaces.bvhStats();
  EXPECT_EQ(st.inputTriangles, 11922u);
  std::printf("city on the device: %zu triangles, %u emissive; BVH %zu nodes, %zu leaves, %zu references, depth %d, "
              "%.1f bytes/triangle (nodes + leaves); Embree build %.1f ms, flatten %.1f ms; all surface buffers "
              "built and uploaded in %.1f ms\n",
              st.inputTriangles, surfaces.emitterCount(), st.nodes, st.leaves, st.references, st.depth,
              st.bytesPerTriangle(), st.buildMs, st.flattenMs, surfaces.uploadMs());
  const geo::TriangleMesh mesh = geo::loadSceneSurfaces(s).mesh;
  const geo::BvhStats plain = geo::buildBvh(mesh, {.spatialSplits = false}).stats;
  std::printf("without spatial splits: %zu nodes, %zu references, depth %d, %.1f bytes/triangle, Embree build %.1f ms\n",
              plain.nodes, plain.references, plain.depth, plain.bytesPerTriangle(), plain.buildMs);
  EXPECT_EQ(plain.references, plain.inputTriangles);
}
