// ReSTIR's mean-field walks (shaders/volume/walk.glsl) against an independent CPU integration of
// the same field: the optical depth of vol_mean_tau, and the collisions of vol_mean_sample (delta
// tracking in the field against the brick majorants), whose distances must follow the field's
// free-flight distribution (a chi-square test of their probability integral transform under the
// CPU's optical depth) and report the field's value there. The field: in each voxel the baked mean
// (bake.h voxelMean), or, in an "exact" voxel (residual bound times the longest chord of the ray's
// direction through a voxel above PLUME_VOL_EXACT_TAU = 0.5), the fine trilinear density itself.
// The ReSTIR Z-tests cannot see a wrong optical depth of the target (p̂ may be any positive
// function), so this test is what guards the walk's voxels, bricks and exact voxels.
#include "core/stats.h"
#include "gpu/pipeline.h"
#include "media/vdb_loader.h"
#include "render/gpu_volume.h"
#include "shaders/shared/bindings.h"
#include "support/gpu_fixture.h"
#include "support/grids.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

using namespace plume;

namespace {

constexpr float kExactTau = 0.5f;  // PLUME_VOL_EXACT_TAU's default (volume/walk.glsl)
constexpr float kMaxTau = 80.0f;   // VOL_MAX_TAU: the depth walk stops once past it

struct Ray {
  glm::vec3 o;
  glm::vec3 d;  // unit, world space
  float tMax;
  float u;  // the ray's own uniform number (the transform of a walk without a collision); its
            // bits seed the walk's random stream
};

constexpr int kRepeats = 32;  // walks per ray, each with its own random stream

// The walk's field at index-space point p for a ray of index-space direction dI (sigma_t, world
// units): the voxel mean, or the trilinear density in an exact voxel; `exact` says which.
float fieldAt(const BakedVolume& vol, float scale, glm::vec3 p, glm::vec3 dI, bool* exact = nullptr) {
  const glm::ivec3 v(glm::floor(p));
  const uint32_t slot = brickSlot(vol, glm::ivec3(v.x >> 3, v.y >> 3, v.z >> 3));
  if (exact) *exact = false;
  if (slot == 0) return 0.0f;
  const glm::ivec3 l = v - glm::ivec3(v.x >> 3, v.y >> 3, v.z >> 3) * 8;
  const size_t i = size_t(slot) * 512 + size_t((l.z * 8 + l.y) * 8 + l.x);
  const float bound = kExactTau * std::max({std::abs(dI.x), std::abs(dI.y), std::abs(dI.z)});
  const bool isExact = scale * vol.voxelResidual[i] > bound;
  if (exact) *exact = isExact;
  return scale * (isExact ? sampleDensity(vol, p) : vol.voxelMean[i]);
}

// Optical depth over (0, t), exactly: the ray cut at every integer plane of index space it
// crosses (all crossings of each axis, sorted), each piece at its voxel's mean times its length,
// or in an exact voxel the trilinear density (a cubic along the piece) by 4-point Gauss-Legendre.
double cpuTau(const BakedVolume& vol, float scale, const Ray& r, double t) {
  const glm::dvec3 oI = glm::dvec3(vol.worldToIndex * glm::vec4(r.o, 1.0f));
  const glm::dvec3 dI = glm::dvec3(glm::mat3(vol.worldToIndex) * r.d);
  std::vector<double> cuts = {0.0, t};
  for (int a = 0; a < 3; ++a) {
    if (std::abs(dI[a]) < 1e-12) continue;
    const double p0 = oI[a], p1 = oI[a] + t * dI[a];
    for (double k = std::ceil(std::min(p0, p1)); k <= std::floor(std::max(p0, p1)); k += 1.0) {
      const double tc = (k - oI[a]) / dI[a];
      if (tc > 0.0 && tc < t) cuts.push_back(tc);
    }
  }
  std::sort(cuts.begin(), cuts.end());
  static const double x[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
  static const double w[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
  double tau = 0.0;
  for (size_t k = 0; k + 1 < cuts.size(); ++k) {
    const double a = cuts[k], b = cuts[k + 1];
    if (!(b > a)) continue;
    bool exact = false;
    const float mid = fieldAt(vol, scale, glm::vec3(oI + 0.5 * (a + b) * dI), glm::vec3(dI), &exact);
    if (!exact) {
      tau += double(mid) * (b - a);
      continue;
    }
    double sum = 0.0;
    for (int g = 0; g < 4; ++g) {
      const double tg = 0.5 * (a + b) + 0.5 * (b - a) * x[g];
      // The voxel of the piece's midpoint (a Gauss point may round onto its face).
      const glm::vec3 p = glm::clamp(glm::vec3(oI + tg * dI), glm::floor(glm::vec3(oI + 0.5 * (a + b) * dI)),
                                     glm::floor(glm::vec3(oI + 0.5 * (a + b) * dI)) + 0.99999f);
      sum += w[g] * double(scale) * double(sampleDensity(vol, p));
    }
    tau += 0.5 * (b - a) * sum;
  }
  return tau;
}

// The midpoint rule of vol_mean_tau_midpoints (ReSTIR's target for light rays), written out
// independently: the ray's part inside the box where the field may be non-zero (the active voxels
// grown by one, index space), cut into n = ceil(length in
// voxels) equal steps, each weighted by the mean of the voxel its midpoint lies in (no exact
// voxels: there the mean, or 0 where the residual bound exceeds twice the mean). The steps are
// placed in float as the shader places them (a step count one off moves every midpoint), the sum
// is taken in double. `exact`: some midpoint lies in an exact voxel.
double cpuMidpoints(const BakedVolume& vol, float scale, const Ray& r, bool& exact) {
  exact = false;
  const glm::vec3 oI = glm::vec3(vol.worldToIndex * glm::vec4(r.o, 1.0f));
  const glm::vec3 dI = glm::vec3(vol.worldToIndex * glm::vec4(r.d, 0.0f));
  const glm::vec3 lo = vol.indexBoundsMin, hi = vol.indexBoundsMax;
  // The slabs as vol_clip_to_bounds takes them (times the reciprocal; an axis the ray does not
  // move along keeps an origin inside [lo, hi]).
  float t0 = 0.0f, t1 = r.tMax;
  for (int a = 0; a < 3; ++a) {
    if (dI[a] == 0.0f) {
      if (oI[a] < lo[a] || oI[a] > hi[a]) return 0.0;
      continue;
    }
    const float inv = 1.0f / dI[a];
    const float ta = (lo[a] - oI[a]) * inv, tb = (hi[a] - oI[a]) * inv;
    t0 = std::max(t0, std::min(ta, tb));
    t1 = std::min(t1, std::max(ta, tb));
  }
  if (!(t0 < t1)) return 0.0;
  const int n = std::max(1, int(std::ceil((t1 - t0) * glm::length(dI))));
  const float h = (t1 - t0) / float(n);
  double sum = 0.0;
  for (int k = 0; k < n; ++k) {
    const glm::ivec3 v(glm::floor(oI + (t0 + (float(k) + 0.5f) * h) * dI));
    const glm::ivec3 b(v.x >> 3, v.y >> 3, v.z >> 3);
    const uint32_t slot = brickSlot(vol, b);
    if (slot == 0) continue;
    const glm::ivec3 l = v - b * 8;
    const size_t i = size_t(slot) * 512 + size_t((l.z * 8 + l.y) * 8 + l.x);
    if (scale * vol.voxelResidual[i] > kExactTau * std::max({std::abs(dI.x), std::abs(dI.y), std::abs(dI.z)})) {
      exact = true;
      if (!(vol.voxelResidual[i] > 2.0f * vol.voxelMean[i])) sum += vol.voxelMean[i];
    } else {
      sum += vol.voxelMean[i];
    }
  }
  return double(scale) * sum * double(h);
}

// Where the ray may meet the field: its (t0, t1) inside the world bounds (t1 <= t0: never).
void clip(const BakedVolume& vol, const Ray& r, double& t0, double& t1) {
  t0 = 0.0;
  t1 = r.tMax;
  for (int a = 0; a < 3; ++a) {
    if (std::abs(r.d[a]) < 1e-12) continue;
    double ta = (vol.worldBoundsMin[a] - r.o[a]) / r.d[a], tb = (vol.worldBoundsMax[a] - r.o[a]) / r.d[a];
    t0 = std::max(t0, std::min(ta, tb));
    t1 = std::min(t1, std::max(ta, tb));
  }
}

class MeanFieldWalk : public test::GpuTest {
 protected:
  struct Result {
    float tau, t, sigma, pad0;
    float midpoints, pad[3];            // vol_mean_tau_midpoints's depth over the ray
  };

  std::vector<Result> run(const BakedVolume& bake, float scale, const std::vector<Ray>& rays) {
    GpuVolumeResources volume(ctx(), bake, scale);
    using gpu::BindingType;
    const uint32_t rayBinding = shared::BIND_MEAN_FIELD + 1, resultBinding = shared::BIND_MEAN_FIELD + 2;
    gpu::ComputePass pass(ctx(), compiler().compile("tests/mean_field_kernel.comp", {}),
                          gpu::bindingTable(resultBinding + 1, {{shared::BIND_ATLAS, BindingType::SampledImage},
                                                                {shared::BIND_INDIRECTION, BindingType::TexelBuffer},
                                                                {shared::BIND_MAJORANTS, BindingType::TexelBuffer},
                                                                {shared::BIND_MEAN_FIELD, BindingType::TexelBuffer}}),
                          4, "mean field walk", glm::uvec3(64, 1, 1));
    volume.bind(pass.set);
    volume.bindMeanField(pass.set);
    std::vector<glm::vec4> words;
    for (const Ray& r : rays) {
      words.push_back(glm::vec4(r.o, r.tMax));
      words.push_back(glm::vec4(r.d, r.u));
    }
    gpu::Buffer rayBuffer(ctx(), words.size() * sizeof(glm::vec4), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "rays");
    rayBuffer.upload(words.data(), words.size() * sizeof(glm::vec4));
    static_assert(sizeof(Result) == 2 * sizeof(glm::vec4), "two vec4 per ray, as the kernel writes them");
    gpu::Buffer out(ctx(), rays.size() * sizeof(Result), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "results");
    // Bindings 5-7 (the frame's, lights', and the path tracer's) are not in the kernel; the
    // table's storage buffers there get the result buffer so that every binding is valid.
    for (uint32_t b = shared::BIND_VOLUME_COUNTERS + 1; b < shared::BIND_MEAN_FIELD; ++b) pass.set.bind(b, out);
    pass.set.bind(rayBinding, rayBuffer);
    pass.set.bind(resultBinding, out);
    const uint32_t count = uint32_t(rays.size());
    ctx().submitAndWait([&](VkCommandBuffer cmd) { pass.record(cmd, glm::uvec3(count, 1, 1), &count); });
    std::vector<Result> res(rays.size());
    out.download(res.data(), res.size() * sizeof(Result));
    EXPECT_EQ(volume.truncatedCount(), 0u);
    return res;
  }

  // Rays from outside the volume towards a point inside, and from points inside; a quarter with
  // a finite tMax.
  static std::vector<Ray> makeRays(const BakedVolume& vol, int n, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> U(0.0f, 1.0f);
    const glm::vec3 lo = vol.worldBoundsMin, hi = vol.worldBoundsMax, c = 0.5f * (lo + hi);
    const float radius = glm::length(hi - lo);
    std::vector<Ray> rays;
    for (int i = 0; i < n; ++i) {
      const glm::vec3 inside = lo + glm::vec3(U(rng), U(rng), U(rng)) * (hi - lo);
      Ray r;
      if (i % 2 == 0) {
        const float z = 2.0f * U(rng) - 1.0f, phi = 6.2831853f * U(rng), s = std::sqrt(1.0f - z * z);
        r.o = c + radius * glm::vec3(s * std::cos(phi), s * std::sin(phi), z);
        r.d = glm::normalize(inside - r.o);
      } else {
        r.o = inside;
        const float z = 2.0f * U(rng) - 1.0f, phi = 6.2831853f * U(rng), s = std::sqrt(1.0f - z * z);
        r.d = glm::vec3(s * std::cos(phi), s * std::sin(phi), z);
      }
      if (i % 8 == 3) r.d = glm::normalize(glm::vec3(r.d.x, 0.0f, r.d.z));  // along a voxel face's plane
      r.tMax = (i % 4 == 1) ? radius * U(rng) : 3.0e38f;
      for (int k = 0; k < kRepeats; ++k) {
        r.u = U(rng);
        rays.push_back(r);
      }
    }
    return rays;
  }

  // Checks every ray; returns the number of exact voxels the CPU integration met (so a test can
  // say it covered them).
  int expectWalksMatch(const BakedVolume& bake, float scale, int n, unsigned seed) {
    const std::vector<Ray> rays = makeRays(bake, n, seed);
    const std::vector<Result> res = run(bake, scale, rays);
    int tauFail = 0, sampleFail = 0, hits = 0, exactHits = 0, misses = 0, midFail = 0, midExact = 0;
    double worstTau = 0.0, worstMid = 0.0, sumTau = 0.0, sumMid = 0.0;
    constexpr int kBins = 16;
    std::vector<double> observed(kBins, 0.0);
    for (size_t i = 0; i < rays.size(); ++i) {
      const Ray& r = rays[i];
      double t0, t1;
      clip(bake, r, t0, t1);
      const double tau = t1 > t0 ? cpuTau(bake, scale, r, std::min<double>(t1, r.tMax)) : 0.0;
      // The depth walk stops once past kMaxTau: beyond, only "at least kMaxTau" is asked.
      const double tol = 2e-3 * tau + 1e-4;
      const double errTau = tau < kMaxTau ? std::abs(res[i].tau - tau) / (tau + 1e-3) : 0.0;
      if (tau < kMaxTau ? std::abs(res[i].tau - tau) > tol : res[i].tau < kMaxTau * (1.0 - 2e-3)) {
        if (++tauFail <= 5) ADD_FAILURE() << "ray " << i << ": tau " << res[i].tau << ", CPU " << tau;
      }
      worstTau = std::max(worstTau, errTau);
      // The midpoint rule's depth, as the CPU computes it (below the transmittance's floor; the
      // walk may stop once past it).
      bool midInExact = false;
      const double mid = cpuMidpoints(bake, scale, r, midInExact);
      midExact += midInExact ? 1 : 0;
      if (mid < kMaxTau) {
        if (!midInExact) {
          sumTau += tau;
          sumMid += mid;
        }
        const double errMid = std::abs(res[i].midpoints - mid);
        worstMid = std::max(worstMid, errMid / (mid + 1e-3));
        if (errMid > 2e-3 * mid + 1e-4) {
          if (++midFail <= 5) ADD_FAILURE() << "ray " << i << ": midpoint depth " << res[i].midpoints << ", CPU " << mid;
        }
      }
      // The collision's probability integral transform under the CPU's optical depth: V = 1 -
      // exp(-tau(0, t)) at a collision, 1 - exp(-tau) + exp(-tau) u without one (tau over the ray),
      // uniform on [0, 1) exactly when the collisions follow the field's free-flight distribution.
      const bool hit = res[i].t >= 0.0f;
      double V = 0.0;
      if (!hit) {
        ++misses;
        V = 1.0 - std::exp(-tau) + std::exp(-tau) * double(r.u);
      } else {
        ++hits;
        if (!(res[i].t <= std::min<double>(t1, r.tMax) * (1.0 + 1e-5))) {
          if (++sampleFail <= 5) ADD_FAILURE() << "ray " << i << ": collision at " << res[i].t << " past the ray's end " << std::min<double>(t1, r.tMax);
          continue;
        }
        V = 1.0 - std::exp(-cpuTau(bake, scale, r, res[i].t));
        const glm::vec3 p = glm::vec3(bake.worldToIndex * glm::vec4(r.o + res[i].t * r.d, 1.0f));
        const glm::vec3 dI = glm::mat3(bake.worldToIndex) * r.d;
        bool exact = false;
        const float sigma = fieldAt(bake, scale, p, dI, &exact);
        exactHits += exact ? 1 : 0;
        // On a voxel's face, edge or corner the GPU's point may round into a neighbour: accept
        // the value of any voxel within 1e-3 index units on each axis.
        const auto near = [&](float s) { return std::abs(res[i].sigma - s) <= 2e-3f * s + 1e-5f; };
        bool anyNear = near(sigma);
        for (int k = 0; k < 27 && !anyNear; ++k) {
          const glm::vec3 off(float(k % 3 - 1), float(k / 3 % 3 - 1), float(k / 9 - 1));
          anyNear = near(fieldAt(bake, scale, p + 1e-3f * off, dI));
        }
        if (!anyNear) {
          if (++sampleFail <= 5) ADD_FAILURE() << "ray " << i << ": sigma at the collision " << res[i].sigma << ", CPU " << sigma;
        }
      }
      observed[std::min(kBins - 1, int(V * kBins))] += 1.0;
    }
    const std::vector<double> expected(kBins, double(rays.size()) / kBins);
    const Chi2Result chi2 = chi2Test(observed, expected);
    EXPECT_TRUE(chi2.pass) << chi2.message << "\n" << chi2.table;
    std::printf("[mean field walk] scale %g: %zu walks, %d collisions (%d in exact voxels); collisions' transform: "
                "chi-square %.1f, %d dof, p %.3f; worst relative error: depth %.2e, midpoint depth %.2e; failures %d / %d / "
                "%d; midpoint rule / exact depth over the rays without exact voxels %.4f (%d walks met exact voxels)\n",
                scale, rays.size(), hits, exactHits, chi2.statistic, chi2.dof, chi2.pValue, worstTau, worstMid, tauFail,
                sampleFail, midFail, sumMid / sumTau, midExact);
    EXPECT_EQ(tauFail, 0);
    EXPECT_EQ(sampleFail, 0);
    EXPECT_EQ(midFail, 0);
    // The midpoint rule approximates the same field: over the rays that meet no exact voxel (there
    // it takes lower bounds) its depth is within 5% of the exact one (a rule that lost bricks or
    // voxels, or a step of the wrong length, is not).
    if (sumTau > 0.0) EXPECT_NEAR(sumMid / sumTau, 1.0, 0.05);
    EXPECT_GT(misses, int(rays.size()) / 8);
    EXPECT_GT(hits, int(rays.size()) / 8);
    return exactHits;
  }
};

}  // namespace

// A smooth cloud at a density where no voxel is exact: the voxel means alone, across bricks.
TEST_F(MeanFieldWalk, DepthAndCollisionsFollowTheVoxelMeans) {
  LoadedGrid loaded;
  loaded.grid = test::makeNoiseGrid(40, 0.05);
  const BakedVolume bake = bakeVolume(loaded);
  EXPECT_EQ(expectWalksMatch(bake, 4.0f, 2048, 11), 0);
}

// The same cloud forty times denser: voxels near steep gradients become exact (the trilinear
// density integrated and inverted in closed form) among ordinary ones.
TEST_F(MeanFieldWalk, DepthAndCollisionsFollowExactVoxelsWhereTheMeanStrays) {
  LoadedGrid loaded;
  loaded.grid = test::makeNoiseGrid(40, 0.05);
  const BakedVolume bake = bakeVolume(loaded);
  EXPECT_GT(expectWalksMatch(bake, 160.0f, 2048, 12), 20);
}
