// Tier c (DESIGN §7): the shared headers compiled as GLSL (run on the Vulkan device) and as C++
// give the same results: RNG streams bit-exact; phase, sampling and the baked trilinear density
// to float rounding.
#include "core/error.h"
#include "gpu/pipeline.h"
#include "media/vdb_loader.h"
#include "render/filter_probe.h"
#include "render/gpu_volume.h"
#include "shaders/shared/phase.h"
#include "shaders/shared/rng.h"
#include "shaders/shared/sampling.h"
#include "support/gpu_fixture.h"
#include "support/grids.h"

#include <glm/glm.hpp>

#include <cmath>

using namespace plume;
namespace sh = plume::shared;

namespace {

struct KernelCase {
  glm::vec4 point;
  glm::vec4 dir;
  glm::uvec4 seed;
};
struct KernelResult {
  glm::uvec4 rng0, rng1;
  glm::vec4 phase, hgDir, coneDir;
  glm::uvec4 walk;
};

class GpuShared : public test::GpuTest {
 protected:
  // Runs shaders/tests/shared_kernels.comp (compiled with `defines`) over `cases` on `volume`.
  std::vector<KernelResult> runKernels(const GpuVolumeResources& volume, const std::vector<KernelCase>& cases,
                                       const gpu::ShaderDefines& defines = {}) {
    const size_t n = cases.size();
    gpu::ComputePass pass(ctx(), compiler().compile("tests/shared_kernels.comp", defines),
                          gpu::bindingTable(7, GpuVolumeResources::bindingTypes(false, false)),
                          4, "shared kernels", glm::uvec3(64, 1, 1));
    volume.bind(pass.set);
    gpu::Buffer in(ctx(), n * sizeof(KernelCase), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "cases");
    gpu::Buffer out(ctx(), n * sizeof(KernelResult), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "results");
    in.upload(cases.data(), n * sizeof(KernelCase));
    pass.set.bind(5, in);
    pass.set.bind(6, out);
    const uint32_t count = uint32_t(n);
    ctx().submitAndWait([&](VkCommandBuffer cmd) { pass.record(cmd, glm::uvec3(count, 1, 1), &count); });
    std::vector<KernelResult> results(n);
    out.download(results.data(), n * sizeof(KernelResult));
    return results;
  }

  // The texture unit's filtered lookup (PLUME_HW_FILTER) against the exact CPU field at 4096
  // points of a noise grid's atlas (a quarter at voxel centres and brick borders), drawn from
  // `seed`: per point the exact value, the spread of the 8 voxels around it (a voxel's value is the
  // field at its centre) and the filtered value's error. Skips where the atlas cannot be filtered.
  struct FilteredLookup {
    float exact, spread;
    double error;
  };
  std::vector<FilteredLookup> filteredLookups(uint32_t seed, glm::ivec3* atlasTexels = nullptr) {
    auto grid = test::makeNoiseGrid(40, 0.05);
    LoadedGrid loaded;
    loaded.grid = grid;
    BakedVolume bake = bakeVolume(loaded);
    if (atlasTexels) *atlasTexels = bake.atlasTexels;
    GpuVolumeResources volume(ctx(), bake, 1.0f);
    try {
      volume.requireLinearFilter();
    } catch (const InputError&) {
      return {};
    }
    const int n = 4096;
    std::vector<KernelCase> cases(n);
    sh::RngState setup = sh::rng_init(glm::uvec2(5, 6), 7, sh::RNG_STREAM_TEST, seed);
    for (int i = 0; i < n; ++i) {
      glm::vec3 p = glm::vec3(-2.0f) + 44.0f * glm::vec3(sh::rng_float(setup), sh::rng_float(setup), sh::rng_float(setup));
      if (i % 4 == 0) p = glm::floor(p);  // voxel centres and brick borders
      cases[i].point = glm::vec4(p, 0.0f);
      cases[i].dir = glm::vec4(0.0f, 0.0f, 1.0f, 0.0f);
    }
    const std::vector<KernelResult> gpu = runKernels(volume, cases, {{"PLUME_HW_FILTER", "1"}});
    std::vector<FilteredLookup> out(n);
    for (int i = 0; i < n; ++i) {
      const glm::vec3 p = glm::vec3(cases[i].point);
      const float exact = sampleDensity(bake, p);
      float lo = exact, hi = exact;
      for (int c = 0; c < 8; ++c) {
        const float v = sampleDensity(bake, glm::floor(p) + glm::vec3(c & 1, (c >> 1) & 1, (c >> 2) & 1));
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
      out[i] = {exact, hi - lo, std::abs(double(gpu[i].phase.z) - exact)};
    }
    return out;
  }
};

}  // namespace

TEST_F(GpuShared, GlslAndCppAgree) {
  auto grid = test::makeNoiseGrid(40, 0.05);
  LoadedGrid loaded;
  loaded.grid = grid;
  BakedVolume bake = bakeVolume(loaded);
  GpuVolumeResources volume(ctx(), bake, 1.0f);

  const int n = 4096;
  std::vector<KernelCase> cases(n);
  sh::RngState setup = sh::rng_init(glm::uvec2(1, 2), 3, sh::RNG_STREAM_TEST, 99);
  const float gs[] = {-0.9f, 0.0f, 0.5f, 0.99f, 0.3f};
  for (int i = 0; i < n; ++i) {
    glm::vec3 p = glm::vec3(-2.0f) + 44.0f * glm::vec3(sh::rng_float(setup), sh::rng_float(setup), sh::rng_float(setup));
    if (i % 3 == 0) p = glm::floor(p);  // voxel centres and brick borders
    cases[i].point = glm::vec4(p, gs[i % 5]);
    glm::vec3 wi = sh::smp_uniform_sphere(sh::rng_float2(setup));
    cases[i].dir = glm::vec4(wi, 2.0f * sh::rng_float(setup) - 1.0f);
    cases[i].seed = glm::uvec4(sh::rng_uint(setup) % 4096, sh::rng_uint(setup) % 4096, i, sh::rng_uint(setup));
  }
  const std::vector<KernelResult> gpuResults = runKernels(volume, cases);

  int rngMismatches = 0, floatMismatches = 0, densityMismatches = 0;
  double worstDensity = 0;
  for (int i = 0; i < n; ++i) {
    const KernelCase& c = cases[i];
    const KernelResult& g = gpuResults[i];
    sh::RngState r = sh::rng_init(glm::uvec2(c.seed), c.seed.z, sh::RNG_STREAM_TEST, c.seed.w);
    glm::uvec4 r0, r1;
    for (int k = 0; k < 4; ++k) r0[k] = sh::rng_uint(r);
    for (int k = 0; k < 4; ++k) r1[k] = sh::rng_uint(r);
    rngMismatches += (r0 != g.rng0) || (r1 != g.rng1);
    const float gg = c.point.w;
    glm::vec2 u = sh::rng_float2(r);
    auto near = [](float a, float b, float rel) { return std::abs(a - b) <= rel * std::max(1.0f, std::abs(b)); };
    bool ok = near(g.phase.x, sh::ph_hg(c.dir.w, gg), 1e-5f) && near(g.phase.y, sh::ph_hg_sample_cos(gg, u.x), 1e-5f);
    glm::vec3 hg = sh::ph_hg_sample(glm::vec3(c.dir), gg, u), cone = sh::smp_uniform_cone(glm::vec3(c.dir), 0.1f, u);
    for (int a = 0; a < 3; ++a) ok = ok && near(g.hgDir[a], hg[a], 1e-4f) && near(g.coneDir[a], cone[a], 1e-4f);
    floatMismatches += !ok;
    sh::RngWalk walk = sh::rng_walk_init(r);
    glm::uvec4 w;
    for (int k = 0; k < 4; ++k) w[k] = sh::rng_walk_next(walk);
    rngMismatches += w != g.walk;
    const float d = sampleDensity(bake, glm::vec3(c.point));
    const double err = std::abs(double(g.phase.z) - d);
    worstDensity = std::max(worstDensity, err);
    densityMismatches += err > 1e-6 * std::max(1.0f, d);
  }
  EXPECT_EQ(rngMismatches, 0) << "RNG streams must be bit-exact";
  EXPECT_EQ(floatMismatches, 0);
  EXPECT_EQ(densityMismatches, 0) << "worst density difference " << worstDensity;
}

// render.density_filter = biased-hardware: the filtered lookup (texture() through the linear
// sampler) against the exact trilinear field. Each of the 3 weights is rounded to the device's
// sub-texel precision (VkPhysicalDeviceLimits::subTexelPrecisionBits), so the error is at most
// 3 * 2^-bits of the spread of the 8 voxels (lavapipe filters floats with float weights: ~0).
TEST_F(GpuShared, HardwareFilteredDensityIsWithinTheDeviceWeightPrecision) {
  const std::vector<FilteredLookup> lookups = filteredLookups(11);
  if (lookups.empty()) GTEST_SKIP() << "the device cannot filter the atlas linearly";
  const double weightStep = std::ldexp(1.0, -int(ctx().limits().subTexelPrecisionBits));
  size_t outside = 0, nonZero = 0;
  double worst = 0;
  for (const FilteredLookup& l : lookups) {
    worst = std::max(worst, l.error);
    outside += l.error > 3.0 * weightStep * l.spread + 1e-6 * std::max(1.0f, l.exact);
    nonZero += l.exact > 0.0f;
  }
  EXPECT_EQ(outside, 0u) << "worst difference " << worst << " (subTexelPrecisionBits "
                         << ctx().limits().subTexelPrecisionBits << ")";
  EXPECT_GT(nonZero, lookups.size() / 4) << "the cases must mostly fall where the grid has density";
}

// render.density_filter auto (render/filter_probe.h): the probe's measure of the texture unit's
// weights, and what follows from it. Where it finds them exact (within 2^-16 of the 8 texels'
// spread; lavapipe: float weights, ~7e-8), the filtered lookup into a real atlas must agree with
// the exact field to that precision as well (plus the atlas coordinate's float rounding), and the
// estimators must read through the filter with auto; elsewhere they must read 8 texels. exact
// never uses the filter, biased-hardware always.
TEST_F(GpuShared, FilterProbeDecidesAutoAndAgreesWithTheAtlasLookups) {
  const double probed = filterWeightError(ctx(), compiler());
  std::printf("[filter] texture unit weights within %.3g of the spread (subTexelPrecisionBits %u)\n", probed,
              ctx().limits().subTexelPrecisionBits);
  EXPECT_EQ(filterWeightError(ctx(), compiler()), probed) << "measured once per context";
  const bool exactFilter = probed <= kExactFilterTolerance;
  EXPECT_EQ(useHardwareFilter(ctx(), compiler(), "auto"), exactFilter);
  EXPECT_FALSE(useHardwareFilter(ctx(), compiler(), "exact"));
  EXPECT_TRUE(useHardwareFilter(ctx(), compiler(), "biased-hardware"));
  if (!exactFilter) return;
  glm::ivec3 extent;
  const std::vector<FilteredLookup> lookups = filteredLookups(13, &extent);
  ASSERT_FALSE(lookups.empty()) << "the probe found the filter exact, so the atlas can be filtered";
  // The atlas coordinate (texel + f + 0.5) / size in float: its fraction is good to the ulp of
  // the largest atlas coordinate, as the exact lookup's is to that of the index-space point.
  const double coordinateUlp = std::ldexp(1.0, -23) * double(std::max({extent.x, extent.y, extent.z}));
  size_t outside = 0;
  double worst = 0;
  for (const FilteredLookup& l : lookups) {
    worst = std::max(worst, l.error / std::max(1e-30, double(l.spread)));
    outside += l.error > 3.0 * (kExactFilterTolerance + 2.0 * coordinateUlp) * l.spread + 1e-6 * std::max(1.0f, l.exact);
  }
  std::printf("[filter] atlas lookups: worst error %.3g of the 8 voxels' spread\n", worst);
  EXPECT_EQ(outside, 0u) << "worst " << worst << " of the spread";
}

// A texel buffer longer than the device allows is bad input (its size follows from the scene),
// refused before anything is allocated, with the buffer named; at the limit it is accepted.
TEST_F(GpuShared, TexelBufferBeyondTheDeviceLimitIsABadInputThatNamesIt) {
  const size_t limit = ctx().limits().maxTexelBufferElements;
  try {
    gpu::TexelBuffer b(ctx(), nullptr, limit + 1, VK_FORMAT_R32_UINT, "the test's mean field");
    FAIL() << "no error for " << limit + 1 << " elements";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("the test's mean field"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(std::to_string(limit)), std::string::npos) << e.what();
  }
  gpu::TexelBuffer small(ctx(), nullptr, 16, VK_FORMAT_R32G32B32A32_UINT, "a small one");
  EXPECT_NE(small.view(), VkBufferView(VK_NULL_HANDLE));
}
