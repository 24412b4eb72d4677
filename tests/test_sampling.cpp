// Tier (a) of DESIGN §7 for shaders/shared/sampling.h: chi-square tests of free-flight
// distances (homogeneous medium), uniform sphere directions and uniform cones (the sun's disk,
// several angular radii). Expected counts are computed here from the exact distributions in
// double precision. Fixed seeds.
#include "core/stats.h"
#include "support/test_support.h"

#include "shaders/shared/rng.h"
#include "shaders/shared/sampling.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <vector>

using namespace plume;
using namespace plume::shared;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kSamples = 1000000;
constexpr double kSigmas = 5.0;

void expectChi2(const std::vector<double>& observed, const std::vector<double>& expected,
                const std::string& name, int tests) {
  test::expectChi2(observed, expected, "sampling_" + name, name, tests);
}

// Free-flight distances with extinction sigma: 100 bins equiprobable under sigma_true
// (t_k = -ln(1 - k/100) / sigma_true, the last one open); returns the counts.
std::vector<double> exponentialCounts(float sigmaSampled, double sigmaTrue, uint seed,
                                      double* mean) {
  constexpr int kBins = 100;
  std::vector<double> observed(kBins, 0.0);
  RngState rng = rng_init(uvec2(seed, 0u), 0u, RNG_STREAM_TEST, 31u);
  double sum = 0.0;
  for (int s = 0; s < kSamples; ++s) {
    const double t = smp_exponential(sigmaSampled, rng_float(rng));
    EXPECT_TRUE(std::isfinite(t) && t >= 0.0) << t;
    sum += t;
    const double cdf = -std::expm1(-sigmaTrue * t);  // 1 - exp(-sigma t), the transmittance's complement
    observed[size_t(std::min(kBins - 1, int(cdf * kBins)))] += 1.0;
  }
  if (mean) *mean = sum / kSamples;
  return observed;
}

// Direction statistics around `axis` measured in double precision: v = 1 - cosTheta computed
// as 2 sin^2(theta/2) from the perpendicular component (accurate for tiny cones), and phi.
struct Polar {
  double v, phi;
};
Polar polarAround(dvec3 axis, dvec3 d) {
  dvec3 a = std::abs(axis.x) < 0.9 ? dvec3(1, 0, 0) : dvec3(0, 1, 0);
  dvec3 t = glm::normalize(glm::cross(axis, a)), b = glm::cross(axis, t);
  const double x = glm::dot(d, t), y = glm::dot(d, b), z = glm::dot(d, axis);
  const double theta = std::atan2(std::sqrt(x * x + y * y), z);
  const double s = std::sin(0.5 * theta);
  return {2.0 * s * s, std::atan2(y, x) + kPi};
}

}  // namespace

TEST(Sampling, ExponentialFreeFlight) {
  const float sigmas[] = {0.5f, 2.0f, 40.0f};
  for (int k = 0; k < 3; ++k) {
    double mean = 0.0;
    std::vector<double> observed = exponentialCounts(sigmas[k], sigmas[k], uint(k), &mean);
    std::vector<double> expected(observed.size(), double(kSamples) / observed.size());
    expectChi2(observed, expected, "exponential" + std::to_string(k), 3);
    // Mean free path 1/sigma; the exponential's standard deviation is also 1/sigma.
    EXPECT_NEAR(mean * sigmas[k], 1.0, kSigmas / std::sqrt(double(kSamples))) << sigmas[k];
  }
}

TEST(Sampling, ExponentialTestCanFail) {
  // Distances sampled with sigma = 1 judged against sigma = 1.01: the test must notice.
  std::vector<double> observed = exponentialCounts(1.0f, 1.01, 9u, nullptr);
  std::vector<double> expected(observed.size(), double(kSamples) / observed.size());
  EXPECT_FALSE(chi2Test(observed, expected).pass);
}

TEST(Sampling, UniformSphere) {
  constexpr int kZBins = 20, kPhiBins = 40;  // equal-area bins: uniform in z and phi
  std::vector<double> observed(kZBins * kPhiBins, 0.0);
  std::vector<double> expected(observed.size(), double(kSamples) / observed.size());
  RngState rng = rng_init(uvec2(1u, 1u), 0u, RNG_STREAM_TEST, 32u);
  for (int s = 0; s < kSamples; ++s) {
    const dvec3 d = dvec3(smp_uniform_sphere(rng_float2(rng)));
    ASSERT_NEAR(glm::length(d), 1.0, 1e-5);
    const int i = std::clamp(int((d.z + 1.0) * 0.5 * kZBins), 0, kZBins - 1);
    const int j = std::clamp(int((std::atan2(d.y, d.x) + kPi) / (2 * kPi) * kPhiBins), 0, kPhiBins - 1);
    observed[size_t(i * kPhiBins + j)] += 1.0;
  }
  expectChi2(observed, expected, "sphere", 1);
}

TEST(Sampling, UniformCone) {
  // Angular radii in radians: the sun (0.2665 degrees), small and wide cones, the hemisphere
  // and a cone wider than it.
  const double radii[] = {0.004651, 0.05, 0.5, kPi / 2, 2.5};
  const vec3 axes[] = {normalize(vec3(0.3f, 1.0f, 0.2f)), vec3(0.0f, 0.0f, 1.0f),
                       normalize(vec3(-1.0f, -0.2f, 0.4f)), vec3(0.0f, -1.0f, 0.0f),
                       normalize(vec3(0.5f, 0.5f, -0.7f))};
  constexpr int kVBins = 20, kPhiBins = 20;
  const int nCones = int(std::size(radii));
  for (int k = 0; k < nCones; ++k) {
    const float vMaxF = float(2.0 * std::sin(0.5 * radii[k]) * std::sin(0.5 * radii[k]));  // 1 - cos
    const double vMax = double(vMaxF);  // the cone the sampler is asked for
    // Uniform in solid angle = uniform in v = 1 - cosTheta on [0, vMax] and in phi; one extra
    // bin of expected count 0 collects directions outside the cone.
    std::vector<double> observed(kVBins * kPhiBins + 1, 0.0);
    std::vector<double> expected(observed.size(), double(kSamples) / (kVBins * kPhiBins));
    expected.back() = 0.0;
    RngState rng = rng_init(uvec2(uint(k), 2u), 0u, RNG_STREAM_TEST, 33u);
    for (int s = 0; s < kSamples; ++s) {
      const dvec3 d = dvec3(smp_uniform_cone(axes[k], vMaxF, rng_float2(rng)));
      ASSERT_NEAR(glm::length(d), 1.0, 1e-5);
      const Polar p = polarAround(dvec3(axes[k]), d);
      const double x = p.v / vMax;
      const int i = x < 1.0 + 1e-4 ? std::min(kVBins - 1, int(x * kVBins)) : -1;
      const int j = std::min(kPhiBins - 1, int(p.phi / (2 * kPi) * kPhiBins));
      observed[i < 0 ? observed.size() - 1 : size_t(i * kPhiBins + j)] += 1.0;
    }
    expectChi2(observed, expected, "cone" + std::to_string(k), nCones);
  }
}

TEST(Sampling, ConeOfZeroRadiusIsTheAxis) {
  const vec3 axis = normalize(vec3(1.0f, 2.0f, 3.0f));
  const vec3 d = smp_uniform_cone(axis, 0.0f, vec2(0.3f, 0.7f));
  EXPECT_NEAR(dot(d, axis), 1.0f, 1e-6f);
  EXPECT_NEAR(smp_uniform_cone_pdf(0.5f), 1.0 / kPi, 1e-6);
  // The versine keeps its precision where 1 - dot does not (the sun's 0.27 degrees).
  const vec3 b = smp_uniform_cone(axis, 1.1e-5f, vec2(1.0f, 0.25f));
  EXPECT_NEAR(smp_versine(axis, b), 1.1e-5f, 1e-9f);
}
