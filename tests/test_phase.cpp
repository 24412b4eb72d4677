// Tier (a) of DESIGN §7 for shaders/shared/phase.h: Henyey–Greenstein integrates to 1 over the
// sphere, its mean cosine is g, ph_hg_sample follows ph_hg (chi-square over cosTheta x phi
// bins, expected counts from the analytic CDF) and the sampled direction obeys the stated
// convention (g > 0 scatters forward: mean dot(wi, wo) = g). Fixed seeds.
#include "core/stats.h"
#include "support/test_support.h"

#include "shaders/shared/phase.h"
#include "shaders/shared/rng.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <vector>

using namespace plume;
using namespace plume::shared;

namespace {

constexpr double kPi = 3.14159265358979323846;
const double kGs[] = {-0.9, 0.0, 0.5, 0.99};
constexpr int kSamples = 1000000;
constexpr int kCosBins = 50;  // equiprobable under the exact distribution
constexpr int kPhiBins = 20;
// Simpson intervals over cosTheta in [-1, 1]: h = 1e-6 resolves the g = 0.99 peak, whose
// width in cosTheta is about (1 - g)^2 = 1e-4.
constexpr int kQuadratureIntervals = 2000000;
constexpr double kQuadratureTolerance = 1e-4;
constexpr double kSigmas = 5.0;

// The HG CDF in cosTheta, in double precision, written independently of phase.h:
// F(mu) = (1 - g^2) / (2g) * (1 / sqrt(1 + g^2 - 2 g mu) - 1 / (1 + g)).
double hgCdf(double g, double mu) {
  if (g == 0.0) return 0.5 * (1.0 + mu);
  return (1.0 - g * g) / (2.0 * g) * (1.0 / std::sqrt(1.0 + g * g - 2.0 * g * mu) - 1.0 / (1.0 + g));
}

double hgInverseCdf(double g, double f) {
  if (g == 0.0) return 2.0 * f - 1.0;
  const double s = 1.0 / (2.0 * g * f / (1.0 - g * g) + 1.0 / (1.0 + g));
  return std::clamp((1.0 + g * g - s * s) / (2.0 * g), -1.0, 1.0);
}

// 2π ∫ f(mu) p(mu) dmu over [-1, 1] by composite Simpson, with ph_hg as the integrand's p.
template <class F>
double integrateOverSphere(double g, F f) {
  const int n = kQuadratureIntervals;
  const double h = 2.0 / n;
  double sum = 0.0;
  for (int i = 0; i <= n; ++i) {
    const double mu = -1.0 + i * h;
    const double w = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
    sum += w * f(mu) * double(ph_hg(float(mu), float(g)));
  }
  return 2.0 * kPi * sum * h / 3.0;
}

struct Frame {
  dvec3 t, b;
};
// An orthonormal frame around w built here (not plume_onb), to measure phi.
Frame frameAround(dvec3 w) {
  dvec3 a = std::abs(w.x) < 0.9 ? dvec3(1, 0, 0) : dvec3(0, 1, 0);
  dvec3 t = glm::normalize(glm::cross(w, a));
  return {t, glm::cross(w, t)};
}

}  // namespace

TEST(Phase, HgIntegratesToOne) {
  for (double g : kGs) {
    EXPECT_NEAR(integrateOverSphere(g, [](double) { return 1.0; }), 1.0, kQuadratureTolerance)
        << "g = " << g;
  }
}

TEST(Phase, HgMeanCosineIsG) {
  for (double g : kGs) {
    EXPECT_NEAR(integrateOverSphere(g, [](double mu) { return mu; }), g, kQuadratureTolerance)
        << "g = " << g;
  }
}

TEST(Phase, HgSamplingMatchesThePdf) {
  const vec3 wiList[] = {normalize(vec3(0.3f, -0.5f, 0.8f)), vec3(0.0f, 0.0f, -1.0f),
                         normalize(vec3(-1.0f, 2.0f, 0.1f)), vec3(0.0f, 1.0f, 0.0f)};
  const int nG = int(std::size(kGs));
  for (int k = 0; k < nG; ++k) {
    const double g = kGs[k];
    const vec3 wi = wiList[k];
    const Frame frame = frameAround(dvec3(wi));
    std::vector<double> edges(kCosBins + 1);
    for (int i = 0; i <= kCosBins; ++i) edges[size_t(i)] = hgInverseCdf(g, double(i) / kCosBins);
    edges.front() = -1.0;
    edges.back() = 1.0;
    std::vector<double> observed(kCosBins * kPhiBins, 0.0), expected(observed.size());
    for (int i = 0; i < kCosBins; ++i) {
      const double pBin = hgCdf(g, edges[size_t(i) + 1]) - hgCdf(g, edges[size_t(i)]);
      for (int j = 0; j < kPhiBins; ++j) expected[size_t(i * kPhiBins + j)] = pBin * kSamples / kPhiBins;
    }
    RngState rng = rng_init(uvec2(uint(k), 0u), 0u, RNG_STREAM_TEST, 21u);
    double sumMu = 0.0, sumMu2 = 0.0;
    for (int s = 0; s < kSamples; ++s) {
      const dvec3 wo = dvec3(ph_hg_sample(wi, float(g), rng_float2(rng)));
      ASSERT_NEAR(glm::length(wo), 1.0, 1e-5);
      const double mu = std::clamp(glm::dot(dvec3(wi), wo), -1.0, 1.0);
      sumMu += mu;
      sumMu2 += mu * mu;
      const double phi = std::atan2(glm::dot(wo, frame.b), glm::dot(wo, frame.t)) + kPi;
      const int i = int(std::upper_bound(edges.begin(), edges.end(), mu) - edges.begin()) - 1;
      const int j = std::min(kPhiBins - 1, int(phi / (2.0 * kPi) * kPhiBins));
      observed[size_t(std::clamp(i, 0, kCosBins - 1) * kPhiBins + j)] += 1.0;
    }
    test::expectChi2(observed, expected, "phase_hg_" + std::to_string(k),
                     "g = " + std::to_string(g) + " (bins: cos-bin * " + std::to_string(kPhiBins) + " + phi-bin)", nG);
    // Convention: wo is the propagation direction after scattering, mean dot(wi, wo) = g.
    const double mean = sumMu / kSamples;
    const double stderr_ = std::sqrt((sumMu2 / kSamples - mean * mean) / kSamples);
    EXPECT_NEAR(mean, g, kSigmas * stderr_ + 1e-6) << "g = " << g;
  }
}

TEST(Phase, HgIsAccurateAtThePeaks) {
  // ph_hg in float against the formula in double, near the forward and backward peaks where
  // 1 + g^2 - 2 g cosTheta cancels; a relative error here is a bias in f / pdf and MIS weights.
  constexpr double kRelTolerance = 1e-5;
  for (double g : {-0.99, -0.9, 0.5, 0.9, 0.99}) {
    for (double oneMinus : {0.0, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3, 0.5}) {
      for (double sign : {1.0, -1.0}) {
        const float mu = float(sign * (1.0 - oneMinus));
        const double d = 1.0 + g * g - 2.0 * g * double(mu);
        const double exact = (1.0 - g * g) / (4.0 * kPi * d * std::sqrt(d));
        EXPECT_NEAR(ph_hg(mu, float(g)) / exact, 1.0, kRelTolerance) << "g " << g << " mu " << mu;
      }
    }
  }
}

TEST(Phase, SampleCosAndSin2AreConsistent) {
  RngState rng = rng_init(uvec2(3u, 0u), 0u, RNG_STREAM_TEST, 23u);
  for (double g : kGs) {
    for (int s = 0; s < 10000; ++s) {
      float sin2 = -1.0f;
      const float mu = ph_hg_sample_cos_sin2(float(g), rng_float(rng), sin2);
      ASSERT_NEAR(sin2, (1.0 - double(mu)) * (1.0 + double(mu)), 4e-6) << g;  // ~30 float ulps
    }
  }
}

TEST(Phase, SampleCosEndpoints) {
  for (double g : kGs) {
    EXPECT_NEAR(ph_hg_sample_cos(float(g), 0.0f), -1.0f, 1e-4f) << g;
    EXPECT_NEAR(ph_hg_sample_cos(float(g), 1.0f), 1.0f, 1e-4f) << g;
  }
}

TEST(Phase, SamplingTestCanFail) {
  // Sampling with g = 0.5 but testing against g = 0.45 must fail the same chi-square.
  const double gTrue = 0.45, gUsed = 0.5;
  std::vector<double> observed(kCosBins, 0.0), expected(kCosBins, double(kSamples) / kCosBins);
  std::vector<double> edges(kCosBins + 1);
  for (int i = 0; i <= kCosBins; ++i) edges[size_t(i)] = hgInverseCdf(gTrue, double(i) / kCosBins);
  edges.back() = 1.0;
  RngState rng = rng_init(uvec2(7u, 0u), 0u, RNG_STREAM_TEST, 22u);
  for (int s = 0; s < kSamples; ++s) {
    const double mu = ph_hg_sample_cos(float(gUsed), rng_float(rng));
    const int i = int(std::upper_bound(edges.begin(), edges.end(), mu) - edges.begin()) - 1;
    observed[size_t(std::clamp(i, 0, kCosBins - 1))] += 1.0;
  }
  EXPECT_FALSE(chi2Test(observed, expected).pass);
}
