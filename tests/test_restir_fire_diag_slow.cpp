// Diagnostics of ReSTIR on the Blender fire's thin wisps (notes/restir.md, "Thin wisps"), disabled:
// run them by hand with --gtest_also_run_disabled_tests. The scene is that of
// GpuEmission.RestirBlenderFireTemporalMatchesReference without emission; environment knobs:
//   DIAG_RUNS (256), DIAG_FRAMES (3), DIAG_ROUNDS (1), DIAG_CAP (20), DIAG_MIS (0 pairwise, 1 GBH),
//   DIAG_M (4), DIAG_K (3), DIAG_RADIUS (2), DIAG_SEQ (0: seed sequence offset), DIAG_REF_SPP
//   (8192), DIAG_REF_SEED (777), DIAG_MASK (1: leave unresolved pixels out of the per-pixel test),
//   DIAG_TOP (pixels listed), DIAG_OUT (EXR of the mean), DIAG_CMP (EXR whose values to list too),
//   DIAG_SIZE, DIAG_FOV, DIAG_SCALE, DIAG_BOUNCES, DIAG_FRAME (20), DIAG_PREV_COPY (1: the previous
//   frame's volume is a second upload of the same bake, so the history is not the same domain and
//   the temporal pass evaluates its cross-domain targets on the previous volume), DIAG_ANIMATED (1:
//   the frames of a run render caches frameNo - 2 (frames - f), each with its predecessor's volume
//   as the history's).
// The reference is cached in /tmp/plume_fire_diag_ref_*.exr (by frame, size, fov, scale, bounces, spp, seed).
#include "io/image.h"
#include "media/bake.h"
#include "render/gpu_volume.h"
#include "media/vdb_loader.h"
#include "reference/reference.h"
#include "render/restir.h"
#include "support/gpu_fixture.h"
#include "support/reference_check.h"
#include "support/resolution.h"
#include "support/run_accumulator.h"
#include "support/scenes.h"
#include "support/test_support.h"

#include <glm/glm.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

using namespace plume;

namespace {

class GpuRestirFireDiag : public test::GpuTest {};

int env(const char* name, int def) {
  const char* v = std::getenv(name);
  return v ? std::atoi(v) : def;
}
float envf(const char* name, float def) {
  const char* v = std::getenv(name);
  return v ? float(std::atof(v)) : def;
}

Scene fireScene() {
  Scene s;
  s.path = "test-scene";
  s.camera.base.position = {1.0f, -2.6f, 1.4f};
  s.camera.base.lookAt = {1.0f, 1.0f, 1.1f};
  s.camera.base.up = {0.0f, 0.0f, 1.0f};
  s.camera.base.fovY = envf("DIAG_FOV", 40.0f);
  s.camera.width = s.camera.height = env("DIAG_SIZE", 16);
  Medium m;
  m.densityScale = envf("DIAG_SCALE", 12.0f);
  m.albedo = glm::vec3(0.5f);
  m.g = 0.2f;
  s.media.push_back(m);
  s.lights = {test::sunLight({0.3f, 1.0f, 0.4f}, {0.3f, 0.3f, 0.35f})};
  s.render.maxBounces = env("DIAG_BOUNCES", 4);
  s.render.seed = 4242;
  return s;
}

// ReSTIR's mean over independent runs against the reference, and the pixels of largest |z|.
TEST_F(GpuRestirFireDiag, DISABLED_AgainstReference) {
  const std::string shared = test::sharedVolumesPath();
  if (shared.empty()) GTEST_SKIP() << test::sharedVolumesMissing();
  const int frameNo = env("DIAG_FRAME", 20);
  char name[64];
  std::snprintf(name, sizeof name, "/fire/fire_%04d.vdb", frameNo);
  auto grid = loadFloatGrid(shared + name, "density").grid;
  Scene s = fireScene();
  RestirOptions o;
  o.radius = env("DIAG_RADIUS", 2);
  o.rounds = env("DIAG_ROUNDS", 1);
  o.historyCap = env("DIAG_CAP", 20);
  o.mis = uint32_t(env("DIAG_MIS", 0));
  o.candidates = env("DIAG_M", 4);
  o.neighbours = env("DIAG_K", 3);
  const int frames = env("DIAG_FRAMES", 3);
  const int runs = env("DIAG_RUNS", 256);
  const int refSpp = env("DIAG_REF_SPP", 8192);
  const std::string refPath = "/tmp/plume_fire_diag_ref_" + std::to_string(frameNo) + "_" + std::to_string(s.camera.width) + "_" +
                              std::to_string(int(s.camera.base.fovY * 100)) + "_" + std::to_string(int(s.media[0].densityScale * 100)) +
                              "_" + std::to_string(s.render.maxBounces) + "_" + std::to_string(refSpp) + "_" + std::to_string(env("DIAG_REF_SEED", 777)) + ".exr";
  Image ref;
  if (std::filesystem::exists(refPath)) {
    ref = readExr(refPath);
  } else {
    const auto t0 = std::chrono::steady_clock::now();
    Scene r = s;
    r.render.spp = refSpp;
    r.render.seed = env("DIAG_REF_SEED", 777);
    ref::ReferenceOptions opt;
    opt.progress = false;
    ref = ref::renderReference(r, grid, opt);
    writeExr(refPath, ref);
    std::printf("reference %.1f s\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  const auto t0 = std::chrono::steady_clock::now();
  LoadedGrid l;
  l.grid = grid;
  l.name = "density";
  BakedVolume bake = bakeVolume(l);
  GpuVolumeResources volume(ctx(), bake, s.medium().densityScale);
  std::unique_ptr<GpuVolumeResources> other;
  if (env("DIAG_PREV_COPY", 0)) other = std::make_unique<GpuVolumeResources>(ctx(), bake, s.medium().densityScale);
  // DIAG_ANIMATED: frame f of a run renders the cache frameNo - 2 (frames - f) (the caches hold
  // every other frame), the previous one's volume bound as the history's; the last is frameNo.
  std::vector<std::unique_ptr<GpuVolumeResources>> animated;
  for (int f = 1; env("DIAG_ANIMATED", 0) && f <= frames; ++f) {
    std::snprintf(name, sizeof name, "/fire/fire_%04d.vdb", frameNo - 2 * (frames - f));
    LoadedGrid g = loadFloatGrid(shared + name, "density");
    animated.push_back(std::make_unique<GpuVolumeResources>(ctx(), bakeVolume(g), s.medium().densityScale));
  }
  Restir restir(ctx(), compiler(), s, o);
  test::RunAccumulator acc;
  uint32_t dropped = 0;
  for (int run = 0; run < runs; ++run) {
    restir.resetHistory();
    Image img;
    for (int f = 1; f <= frames; ++f) {
      if (!animated.empty()) {
        restir.setVolumes(*animated[size_t(f - 1)], *animated[size_t(std::max(f - 2, 0))]);
      } else {
        restir.setVolumes(volume, other ? *other : volume);
      }
      img = restir.renderFrame(f, uint32_t(run + 1 + env("DIAG_SEQ", 0)));
    }
    dropped += restir.takeDroppedCount();
    acc.add(img);
  }
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  Image mean = acc.image(s.camera.width, s.camera.height);
  test::ReferenceCheckOptions opt;
  opt.imageMeanVariance = acc.imageMeanVariance();
  opt.outputGroup = "diag";
  if (env("DIAG_MASK", 1)) {
    const auto map = test::referenceResolution(s, *grid, refSpp);
    opt.unresolved = map.unresolvedMask();
    std::printf("resolution: %d empty, %d resolved, %d unresolved\n", map.count(test::PixelResolution::Empty),
                map.count(test::PixelResolution::Resolved), map.count(test::PixelResolution::Unresolved));
  }
  auto check = test::checkAgainstReference(mean, ref, opt);
  std::printf("%s frames %d runs %d: %.1f s dropped %u\n%s\n", o.name().c_str(), frames, runs, secs, dropped,
              check.summary().c_str());
  // worst pixels (channel R of the check's z)
  std::vector<std::pair<double, int>> zs;
  const int n = s.camera.width * s.camera.height;
  double imean = 0;
  for (int i = 0; i < n; ++i) zs.push_back({check.pixels.z[3 * i], i}), imean += ref.rgb[3 * i] / n;
  std::sort(zs.begin(), zs.end(), [](auto a, auto b) { return std::abs(a.first) > std::abs(b.first); });
  std::printf("  ref image mean R %.5g\n", imean);
  Image cmp;
  if (const char* c = std::getenv("DIAG_CMP")) cmp = readExr(c);
  for (int k = 0; k < env("DIAG_TOP", 6); ++k) {
    const int i = zs[k].second;
    std::printf("  pixel (%d, %d) z %.2f  mean %.5g (se %.3g) ref %.5g (se %.3g)\n", i % s.camera.width, i / s.camera.width,
                zs[k].first, mean.rgb[3 * i], std::sqrt(mean.var[3 * i]), ref.rgb[3 * i], std::sqrt(ref.var[3 * i]));
    if (!cmp.rgb.empty()) std::printf("      cmp %.5g (se %.3g)\n", cmp.rgb[3 * i], std::sqrt(cmp.var[3 * i]));
  }
  if (const char* out = std::getenv("DIAG_OUT")) writeExr(out, mean);
}

// Each pixel's first-collision probability P and class (support/resolution.h) at DIAG_REF_SPP.
TEST(RestirFireDiag, DISABLED_PixelCollisionProbabilities) {
  const std::string shared = test::sharedVolumesPath();
  if (shared.empty()) GTEST_SKIP() << test::sharedVolumesMissing();
  auto grid = loadFloatGrid(shared + "/fire/fire_0020.vdb", "density").grid;
  const Scene s = fireScene();
  const int spp = env("DIAG_REF_SPP", 8192);
  const test::ResolutionMap map = test::referenceResolution(s, *grid, spp, 1, env("DIAG_RAYS", 16));
  const char* kind[] = {"empty", "resolved", "unresolved"};
  for (int i = 0; i < map.width * map.height; ++i) {
    std::printf("pixel (%d, %d): P %.4g, N*P %.4g, %s\n", i % map.width, i / map.width, map.collisionProbability[size_t(i)],
                spp * map.collisionProbability[size_t(i)], kind[int(map.pixels[size_t(i)])]);
  }
}

}  // namespace
