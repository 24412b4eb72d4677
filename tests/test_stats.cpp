// Tests of src/core/stats: the incomplete gamma and normal functions against known values, the
// chi-square helper (accepts the right distribution, rejects a slightly wrong one, pools small
// bins), relMSE, and the per-pixel Z-tests (pass for two independent estimates of the same
// image, fail for a bias of a few standard errors in a region); the shaders' running mean and
// variance (shared/accumulate.h). Fixed seeds.
#include "core/error.h"
#include "core/stats.h"
#include "io/failure_images.h"
#include "io/image.h"
#include "support/test_support.h"

#include "shaders/shared/accumulate.h"
#include "shaders/shared/rng.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <filesystem>
#include <limits>
#include <vector>

using namespace plume;
using shared::RngState;

namespace {

constexpr int kSamples = 1000000;

// Draws kSamples from the discrete distribution `p` (normalised here) by inverse CDF.
std::vector<double> sampleCounts(std::vector<double> p, uint32_t seed) {
  double sum = 0.0;
  for (double& x : p) sum += x;
  std::vector<double> cdf, counts(p.size(), 0.0);
  double acc = 0.0;
  for (double x : p) cdf.push_back(acc += x / sum);
  RngState rng = shared::rng_init(glm::uvec2(seed, 0u), 0u, shared::RNG_STREAM_TEST, 41u);
  for (int s = 0; s < kSamples; ++s) {
    const double u = shared::rng_float(rng);
    const size_t i = size_t(std::upper_bound(cdf.begin(), cdf.end(), u) - cdf.begin());
    counts[std::min(i, p.size() - 1)] += 1.0;
  }
  return counts;
}

std::vector<double> expectedCounts(const std::vector<double>& p) {
  double sum = 0.0;
  for (double x : p) sum += x;
  std::vector<double> e;
  for (double x : p) e.push_back(kSamples * x / sum);
  return e;
}

std::vector<double> linearWeights(int n, double tilt) {
  std::vector<double> p;
  for (int i = 0; i < n; ++i) p.push_back(1.0 + i + tilt * i * i);
  return p;
}

constexpr int kSamplesPerPixel = 256;  // enough that the estimated variance is accurate

// A pixel estimate: the mean of `n` noisy samples of `truth` (uniform noise of standard
// deviation 0.3 * truth) and the variance of that mean estimated from the samples.
struct Estimate {
  float mean, varianceOfMean;
};
Estimate estimate(float truth, int n, RngState& rng) {
  double sum = 0.0, sumSq = 0.0;
  for (int i = 0; i < n; ++i) {
    const double x = truth * (1.0 + 0.3 * std::sqrt(12.0) * (shared::rng_float(rng) - 0.5));
    sum += x;
    sumSq += x * x;
  }
  const double mean = sum / n, var = (sumSq - n * mean * mean) / (n - 1);
  return {float(mean), float(var / n)};
}

float truthAt(int x, int y, int c) {
  return 0.5f + 0.4f * std::sin(0.2f * float(x) + 0.7f * float(c)) * std::cos(0.15f * float(y));
}

// A noisy estimate of the truth image; `bias` standard errors are added inside `region`.
Image noisyImage(int w, int h, uint32_t seed, double bias = 0.0, int regionSize = 0) {
  Image img;
  img.width = w;
  img.height = h;
  img.rgb.assign(size_t(3 * w * h), 0.0f);
  img.var.assign(img.rgb.size(), 0.0f);
  RngState rng = shared::rng_init(glm::uvec2(seed, 1u), 0u, shared::RNG_STREAM_TEST, 42u);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < 3; ++c) {
        const size_t i = size_t(3 * (y * w + x) + c);
        Estimate e = estimate(truthAt(x, y, c), kSamplesPerPixel, rng);
        const bool inRegion = x >= 8 && x < 8 + regionSize && y >= 8 && y < 8 + regionSize;
        img.rgb[i] = e.mean + (inRegion ? float(bias * std::sqrt(e.varianceOfMean)) : 0.0f);
        img.var[i] = e.varianceOfMean;
      }
    }
  }
  return img;
}

}  // namespace

TEST(Stats, IncompleteGammaKnownValues) {
  for (double x : {0.01, 0.5, 1.0, 3.0, 10.0, 40.0}) {
    EXPECT_NEAR(regularizedGammaQ(1.0, x), std::exp(-x), 1e-12) << x;
    EXPECT_NEAR(regularizedGammaQ(0.5, x), std::erfc(std::sqrt(x)), 1e-12) << x;
    for (double a : {0.5, 2.0, 7.5, 200.0}) {
      EXPECT_NEAR(regularizedGammaP(a, x) + regularizedGammaQ(a, x), 1.0, 1e-12);
    }
  }
  EXPECT_EQ(regularizedGammaQ(3.0, 0.0), 1.0);
  // Chi-square critical values at p = 0.01 (tables): dof 1: 6.6349, dof 10: 23.2093,
  // dof 100: 135.8067.
  EXPECT_NEAR(chi2SurvivalFunction(6.6349, 1), 0.01, 1e-5);
  EXPECT_NEAR(chi2SurvivalFunction(23.2093, 10), 0.01, 1e-5);
  EXPECT_NEAR(chi2SurvivalFunction(135.8067, 100), 0.01, 1e-5);
  EXPECT_NEAR(chi2SurvivalFunction(999.0 - 0.0, 999), 0.49, 0.01);  // median ~ dof - 2/3
}

TEST(Stats, NormalFunctions) {
  EXPECT_NEAR(normalCdf(0.0), 0.5, 1e-15);
  EXPECT_NEAR(normalCdf(1.959963985), 0.975, 1e-9);
  EXPECT_NEAR(normalCdf(-3.0), 0.0013498980316301, 1e-12);
  EXPECT_NEAR(twoSidedPValue(-1.959963985), 0.05, 1e-9);
  EXPECT_NEAR(twoSidedPValue(2.575829304), 0.01, 1e-9);
  EXPECT_NEAR(sidakLevel(0.01, 1.0), 0.01, 1e-15);
  EXPECT_NEAR(sidakLevel(0.05, 1e6), 5.129329e-8, 1e-13);
}

TEST(Stats, Chi2AcceptsTheRightDistribution) {
  const std::vector<double> p = linearWeights(40, 0.05);
  Chi2Result r = chi2Test(sampleCounts(p, 1), expectedCounts(p));
  EXPECT_TRUE(r.pass) << r.table;
  EXPECT_EQ(r.dof, 39);
  EXPECT_TRUE(r.message.empty());
}

TEST(Stats, Chi2RejectsASlightlyWrongDistribution) {
  // Samples drawn with the quadratic term 10% larger than the one tested (bin probabilities
  // off by at most 2%).
  Chi2Result r = chi2Test(sampleCounts(linearWeights(40, 0.055), 2),
                          expectedCounts(linearWeights(40, 0.05)));
  EXPECT_FALSE(r.pass);
  EXPECT_NE(r.table.find("FAILED"), std::string::npos) << r.table;
  EXPECT_NE(r.table.find("(O-E)^2/E"), std::string::npos);
}

TEST(Stats, Chi2PoolsSmallBins) {
  // 30 bins of expected count ~0.3 (9 together) and 10 large ones: the small ones are pooled.
  std::vector<double> p(40, 1.0);
  for (int i = 0; i < 30; ++i) p[size_t(i)] = 3e-6;
  const std::vector<double> e = expectedCounts(p);
  Chi2Result r = chi2Test(sampleCounts(p, 3), e);
  EXPECT_TRUE(r.pass) << r.table;
  EXPECT_EQ(r.pooledBins, 30);
  EXPECT_EQ(r.dof, 10);  // 10 bins + the pool - 1
}

TEST(Stats, Chi2FailsOnSamplesWhereNoneAreExpected) {
  std::vector<double> observed = {500.0, 480.0, 20.0}, expected = {500.0, 500.0, 0.0};
  Chi2Result r = chi2Test(observed, expected);
  EXPECT_FALSE(r.pass);
  EXPECT_NE(r.message.find("expected count 0"), std::string::npos) << r.message;
}

TEST(Stats, RelMse) {
  Image a = noisyImage(16, 8, 5);
  EXPECT_EQ(relMse(a, a), 0.0);
  const std::vector<float> x = {1.1f, 0.0f}, r = {1.0f, 0.1f};
  EXPECT_NEAR(relMse(x, r), 0.5 * (0.01 / 1.01 + 0.01 / 0.02), 1e-7);
  Image b = noisyImage(8, 8, 5);
  EXPECT_THROW(relMse(a, b), InputError);
  EXPECT_NEAR(meanRatio(std::vector<float>{2, 4}, std::vector<float>{1, 2}), 2.0, 1e-12);
  EXPECT_EQ(meanRatio(std::vector<float>{0, 0}, std::vector<float>{0, 0}), 1.0);
}

TEST(Stats, WorstPixelsAndTheirShares) {
  Image ref = noisyImage(8, 4, 6), x = ref;
  EXPECT_EQ(shareOfWorst(x, ref, 0.01), 0.0);  // no error at all
  // Errors in two pixels only: (5, 2) three times the squared error of (1, 0), in one channel each.
  const auto at = [&](int px, int py, int c) { return size_t(3 * (py * 8 + px) + c); };
  const double r0 = ref.rgb[at(1, 0, 1)], r1 = ref.rgb[at(5, 2, 2)];
  x.rgb[at(1, 0, 1)] += float(0.1 * std::sqrt(r0 * r0 + 1e-2));
  x.rgb[at(5, 2, 2)] += float(0.1 * std::sqrt(3.0) * std::sqrt(r1 * r1 + 1e-2));
  const std::vector<PixelError> w = worstPixels(x, ref, 3);
  ASSERT_EQ(w.size(), 3u);
  EXPECT_EQ(w[0].x, 5);
  EXPECT_EQ(w[0].y, 2);
  EXPECT_NEAR(w[0].share, 0.75, 1e-4);
  EXPECT_EQ(w[1].x, 1);
  EXPECT_EQ(w[1].y, 0);
  EXPECT_NEAR(w[1].share, 0.25, 1e-4);
  EXPECT_EQ(w[2].share, 0.0);
  EXPECT_NEAR(shareOfWorst(x, ref, 0.01), 0.75, 1e-4);  // 1% of 32 pixels: one pixel
  EXPECT_NEAR(shareOfWorst(x, ref, 2.0 / 32.0), 1.0, 1e-9);
  EXPECT_EQ(worstPixels(x, ref, 100).size(), 32u);
  EXPECT_THROW(worstPixels(x, noisyImage(4, 4, 6), 1), InputError);
}

TEST(Stats, ZTestPassesIndependentEstimatesOfTheSameImage) {
  for (uint32_t seed = 0; seed < 4; ++seed) {
    const Image a = noisyImage(64, 64, 10 + seed), b = noisyImage(64, 64, 20 + seed);
    const ZTestResult r = zTest(a, b);
    if (!r.pass) writeFailureImages(test::outputDir("stats_ztest_pass"), "same", a, b, r);
    EXPECT_TRUE(r.pass) << r.summary();
    EXPECT_EQ(r.tests, 3u * 64u * 64u);
    EXPECT_NEAR(r.meanRatio, 1.0, 0.01);
    EXPECT_LT(r.relMse, 1e-3);
  }
}

TEST(Stats, ZTestFailsABiasOfAFewStandardErrorsInARegion) {
  // a is biased by 5 of its standard errors in a 16x16 region: z ~ 5/sqrt(2) = 3.5 there,
  // below the Šidák threshold (~4.9) for most single channels, yet the test must notice.
  const Image a = noisyImage(64, 64, 30, 5.0, 16), b = noisyImage(64, 64, 40);
  const ZTestResult r = zTest(a, b);
  EXPECT_FALSE(r.pass) << r.summary();
  EXPECT_GT(r.failingPixels, 0u);
  EXPECT_LT(r.failingFraction, 16.0 * 16.0 / (64.0 * 64.0));
  EXPECT_TRUE(r.worstX >= 8 && r.worstX < 24 && r.worstY >= 8 && r.worstY < 24) << r.summary();
  EXPECT_GT(r.worstZ, 0.0);
  // The failure report: both inputs, the z-scores and the summary.
  const std::string dir = test::outputDir("stats_ztest_biased");
  writeFailureImages(dir, "biased", a, b, r);
  for (const char* f : {"biased_a.exr", "biased_b.exr", "biased_z.exr", "biased_summary.txt"}) {
    EXPECT_TRUE(std::filesystem::exists(std::filesystem::path(dir) / f)) << f;
  }
  const Image z = readExr(dir + "/biased_z.exr");
  EXPECT_EQ(z.rgb.size(), a.rgb.size());
}

TEST(Stats, ZTestAgainstExactValues) {
  const int w = 32, h = 32;
  std::vector<float> truth(size_t(3 * w * h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) truth[size_t(3 * (y * w + x) + c)] = truthAt(x, y, c);
  EXPECT_TRUE(zTestAgainst(noisyImage(w, h, 50), truth).pass);
  const ZTestResult biased = zTestAgainst(noisyImage(w, h, 51, 6.0, 8), truth);
  EXPECT_FALSE(biased.pass) << biased.summary();
  // A constant: every pixel of a flat estimate around 0.5.
  Image flat = noisyImage(w, h, 52);
  RngState rng = shared::rng_init(glm::uvec2(0u, 0u), 0u, shared::RNG_STREAM_TEST, 43u);
  for (size_t i = 0; i < flat.rgb.size(); ++i) {
    const Estimate e = estimate(0.5f, kSamplesPerPixel, rng);
    flat.rgb[i] = e.mean;
    flat.var[i] = e.varianceOfMean;
  }
  EXPECT_TRUE(zTestAgainst(flat, glm::vec3(0.5f)).pass);
  EXPECT_FALSE(zTestAgainst(flat, glm::vec3(0.5f, 0.5f, 0.52f)).pass);
}

TEST(Stats, ZTestZeroVarianceAndNonFinite) {
  Image a;
  a.width = 2;
  a.height = 1;
  a.rgb = {1.0f, 0.0f, 2.0f, 3.0f, 4.0f, 5.0f};
  a.var.assign(6, 0.0f);
  Image b = a;
  EXPECT_TRUE(zTest(a, b).pass);  // exact matches where both variances are 0
  b.rgb[2] = 2.0f * (1.0f + 1e-5f);
  EXPECT_TRUE(zTest(a, b).pass);  // within the relative precision floor (kZTestRelativePrecision)
  b.rgb[2] = 2.001f;              // 5 times the floor
  ZTestResult r = zTest(a, b);
  EXPECT_FALSE(r.pass);
  EXPECT_EQ(r.failingPixels, 1u);
  EXPECT_NEAR(r.worstZ, -5.0, 0.01);  // z = (a - b) / sigma, a = 2 < b
  EXPECT_EQ(r.worstX, 0);
  EXPECT_EQ(r.worstChannel, 2);
  b = a;
  b.rgb[1] = 1e-30f;  // a non-zero value against an exact 0 with no variance: far outside
  r = zTest(a, b);
  EXPECT_FALSE(r.pass);
  EXPECT_EQ(r.worstChannel, 1);
  b.rgb[1] = 1e-37f;  // ~8.5 times the absolute floor (the smallest normal float)
  r = zTest(a, b);
  EXPECT_FALSE(r.pass);
  EXPECT_NEAR(r.worstZ, -1e-37 / double(std::numeric_limits<float>::min()), 0.01);
  b.rgb[1] = 1.68e-44f;  // a denormal (the Blender fire's red tail): float rounding, not a bias
  EXPECT_TRUE(zTest(a, b).pass);
  b = a;
  b.rgb[4] = std::numeric_limits<float>::quiet_NaN();
  b.var[4] = 1.0f;
  r = zTest(a, b);
  EXPECT_FALSE(r.pass);
  EXPECT_EQ(r.worstX, 1);
}

TEST(Stats, ZTestRefusesBadInput) {
  Image a = noisyImage(8, 8, 60), b = noisyImage(8, 4, 61), c = noisyImage(8, 8, 62);
  EXPECT_THROW(zTest(a, b), InputError);
  c.var.clear();
  EXPECT_THROW(zTest(a, c), InputError);
  EXPECT_THROW(zTestAgainst(c, glm::vec3(1.0f)), InputError);
  EXPECT_THROW(zTestAgainst(a, std::vector<float>(5)), InputError);
}

// The renderers' accumulation (shared/accumulate.h): samples merged one at a time (ReSTIR's
// shading) or in batches (the path tracer) give the two-pass mean and M2.
TEST(Stats, AccumulationMergesMatchTwoPassMeanAndVariance) {
  std::vector<glm::vec3> x;
  uint32_t h = 12345u;
  for (int i = 0; i < 100; ++i) {
    glm::vec3 v;
    for (int c = 0; c < 3; ++c) {
      h = h * 1664525u + 1013904223u;
      v[c] = float(h >> 8) / float(1u << 24) * float(c + 1) + 10.0f;
    }
    x.push_back(v);
  }
  glm::dvec3 mean(0.0), m2(0.0);
  for (const glm::vec3& v : x) mean += glm::dvec3(v) / double(x.size());
  for (const glm::vec3& v : x) m2 += (glm::dvec3(v) - mean) * (glm::dvec3(v) - mean);
  glm::vec4 one(0.0f), batched(0.0f);
  glm::vec3 m2One(0.0f), m2Batched(0.0f);
  for (const glm::vec3& v : x) shared::acc_merge(one, m2One, v, glm::vec3(0.0f), 1.0f);
  for (size_t b = 0; b < x.size(); b += 16) {  // batches of 16 (the last one 4)
    glm::vec4 batch(0.0f);
    glm::vec3 m2Batch(0.0f);
    for (size_t i = b; i < std::min(x.size(), b + 16); ++i) shared::acc_merge(batch, m2Batch, x[i], glm::vec3(0.0f), 1.0f);
    shared::acc_merge(batched, m2Batched, glm::vec3(batch), m2Batch, batch.w);
  }
  for (const auto& [acc, accM2] : {std::pair{one, m2One}, std::pair{batched, m2Batched}}) {
    EXPECT_EQ(acc.w, 100.0f);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(acc[c], mean[c], 1e-5 * mean[c]) << c;
      EXPECT_NEAR(accM2[c], m2[c], 1e-4 * m2[c]) << c;
    }
  }
  glm::vec4 empty(0.0f);
  glm::vec3 m2Empty(0.0f);
  shared::acc_merge(empty, m2Empty, glm::vec3(1.0f), glm::vec3(0.0f), 0.0f);  // nothing to add
  EXPECT_EQ(empty, glm::vec4(0.0f));
}
