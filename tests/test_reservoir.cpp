// Tier (b) of DESIGN §7 for shaders/shared/reservoir.h: selection frequencies of streaming
// resampling match w / Σw, merging equals streaming, and the packed form round-trips and drops
// non-finite weights. Fixed seeds; random numbers from rng.h as on the GPU.
#include "core/stats.h"
#include "support/test_support.h"

#include "shaders/shared/reservoir.h"
#include "shaders/shared/rng.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <vector>

using namespace plume;
using namespace plume::shared;

namespace {

constexpr int kTrials = 1000000;
constexpr double kRelTolerance = 0.02;  // DESIGN §7: within 2% of w / Σw
// Bins whose expected count is at least this are held to kRelTolerance (2% is then > 4.5
// standard deviations of a binomial count, so a correct sampler passes and a biased one fails).
constexpr double kMinExpectedForRelCheck = 50000.0;
// Five standard deviations: the bound for bins too small for the relative check.
constexpr double kSigmas = 5.0;

// Streams the candidates (weights used directly as resampling weights) and returns the index
// of the selected one, or -1. Confidence 1 each.
int streamOnce(const std::vector<double>& w, size_t begin, size_t end, RngState& rng,
               RsReservoir& r) {
  int selected = -1;
  for (size_t i = begin; i < end; ++i) {
    if (rs_update(r, float(w[i]), 1.0f + float(i), 1.0f, rng_float(rng))) selected = int(i);
  }
  return selected;
}

std::vector<double> expectedCounts(const std::vector<double>& w, double trials) {
  const double sum = std::accumulate(w.begin(), w.end(), 0.0);
  std::vector<double> e;
  for (double x : w) e.push_back(trials * x / sum);
  return e;
}

void expectFrequencies(const std::vector<double>& counts, const std::vector<double>& w,
                       const std::string& name) {
  const std::vector<double> e = expectedCounts(w, kTrials);
  for (size_t i = 0; i < w.size(); ++i) {
    if (w[i] == 0.0) {
      EXPECT_EQ(counts[i], 0.0) << name << ": zero weight " << i << " was selected";
    } else if (e[i] >= kMinExpectedForRelCheck) {
      EXPECT_NEAR(counts[i] / e[i], 1.0, kRelTolerance) << name << ": candidate " << i;
    } else {
      EXPECT_NEAR(counts[i], e[i], kSigmas * std::sqrt(e[i]) + 1.0) << name << ": candidate " << i;
    }
  }
  if (std::count_if(e.begin(), e.end(), [](double x) { return x > 0.0; }) < 2) return;
  test::expectChi2(counts, e, "reservoir_" + name, name);
}

const std::vector<std::vector<double>>& weightSets() {
  static const std::vector<std::vector<double>> sets = {
      {1.0, 2.0, 3.0, 4.0},
      {5.0, 1e-5, 2.0, 0.0, 3.0},      // one tiny and one zero weight
      {0.0, 7.0},                      // zero first: the second must always win
      {0.3, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3, 10.0, 0.001},
  };
  return sets;
}

}  // namespace

TEST(Reservoir, StreamingSelectsInProportionToWeights) {
  for (size_t s = 0; s < weightSets().size(); ++s) {
    const std::vector<double>& w = weightSets()[s];
    RngState rng = rng_init(uvec2(uint(s), 0u), 0u, RNG_STREAM_TEST, 11u);
    std::vector<double> counts(w.size(), 0.0);
    for (int t = 0; t < kTrials; ++t) {
      RsReservoir r = rs_empty();
      int sel = streamOnce(w, 0, w.size(), rng, r);
      ASSERT_GE(sel, 0);
      EXPECT_FLOAT_EQ(r.p_hat, 1.0f + float(sel));  // the caller's sample and p̂ agree
      counts[size_t(sel)] += 1.0;
    }
    expectFrequencies(counts, w, "stream" + std::to_string(s));
  }
}

TEST(Reservoir, StreamingCanFailWhenTheSelectionIsWrong) {
  // The same check on a deliberately wrong rule (select when u < 0.5 w / w_sum) must fail:
  // proves the tolerance and chi-square above can detect a biased selection.
  const std::vector<double> w = {1.0, 2.0, 3.0, 4.0};
  RngState rng = rng_init(uvec2(9u, 9u), 0u, RNG_STREAM_TEST, 12u);
  std::vector<double> counts(w.size(), 0.0);
  for (int t = 0; t < kTrials; ++t) {
    double sum = 0.0;
    int sel = 0;
    for (size_t i = 0; i < w.size(); ++i) {
      sum += w[i];
      if (rng_float(rng) * sum < (i == 0 ? 1.0 : 0.95) * w[i]) sel = int(i);
    }
    counts[size_t(sel)] += 1.0;
  }
  EXPECT_FALSE(chi2Test(counts, expectedCounts(w, kTrials)).pass);
}

TEST(Reservoir, StreamWeightIsTargetOverSourcePdf) {
  RsReservoir r = rs_empty();
  EXPECT_TRUE(rs_stream(r, 3.0f, 0.5f, 0.25f, 0.0f));  // w = 0.25 * 3 / 0.5
  EXPECT_FLOAT_EQ(r.w_sum, 1.5f);
  EXPECT_FALSE(rs_stream(r, 2.0f, 0.0f, 0.25f, 0.0f));  // pdf 0: weight 0, M still counts
  EXPECT_FLOAT_EQ(r.w_sum, 1.5f);
  EXPECT_FLOAT_EQ(r.M, 2.0f);
  rs_finalize(r);
  EXPECT_FLOAT_EQ(r.W, 0.5f);  // w_sum / p̂ = 1.5 / 3
}

TEST(Reservoir, RisEstimateIsUnbiased) {
  // RIS with M = 4 candidates from a uniform source on [0,1), target p̂(x) = x + 0.1 and
  // integrand f(x) = x^2: mean of f(Y) W equals ∫ f = 1/3 (GRIS Eq. 3.3 with m = 1/M).
  constexpr int kM = 4, kRuns = 400000;
  RngState rng = rng_init(uvec2(1u, 2u), 0u, RNG_STREAM_TEST, 13u);
  double sum = 0.0, sumSq = 0.0;
  for (int t = 0; t < kRuns; ++t) {
    RsReservoir r = rs_empty();
    float y = 0.0f;
    for (int i = 0; i < kM; ++i) {
      float x = rng_float(rng);
      if (rs_stream(r, x + 0.1f, 1.0f, 1.0f / kM, rng_float(rng))) y = x;
    }
    rs_finalize(r);
    const double est = double(y) * y * r.W;
    sum += est;
    sumSq += est * est;
  }
  const double mean = sum / kRuns, stderr_ = std::sqrt((sumSq / kRuns - mean * mean) / kRuns);
  EXPECT_NEAR(mean, 1.0 / 3.0, kSigmas * stderr_);
}

TEST(Reservoir, MergeOfTwoHalvesEqualsStreamingAll) {
  // Each half is streamed with MIS weight 1/N into its own reservoir; merging them with the
  // identity shift (p̂ unchanged, Jacobian 1) and m = 1 gives w = p̂ W = w_sum of the half,
  // so the merged w_sum, M and selection distribution equal streaming all N candidates.
  for (size_t s = 0; s < weightSets().size(); ++s) {
    const std::vector<double>& w = weightSets()[s];
    const size_t half = w.size() / 2;
    RngState rng = rng_init(uvec2(uint(s), 1u), 0u, RNG_STREAM_TEST, 14u);
    std::vector<double> counts(w.size(), 0.0);
    for (int t = 0; t < kTrials; ++t) {
      RsReservoir a = rs_empty(), b = rs_empty();
      int selA = streamOnce(w, 0, half, rng, a);
      int selB = streamOnce(w, half, w.size(), rng, b);
      rs_finalize(a);
      rs_finalize(b);
      RsReservoir merged = rs_empty();
      int sel = -1;
      if (rs_merge(merged, a, a.p_hat, 1.0f, 1.0f, rng_float(rng))) sel = selA;
      if (rs_merge(merged, b, b.p_hat, 1.0f, 1.0f, rng_float(rng))) sel = selB;
      ASSERT_GE(sel, 0);
      ASSERT_FLOAT_EQ(merged.M, float(w.size()));
      ASSERT_NEAR(merged.w_sum, std::accumulate(w.begin(), w.end(), 0.0), 1e-5);
      counts[size_t(sel)] += 1.0;
    }
    expectFrequencies(counts, w, "merge" + std::to_string(s));
  }
}

TEST(Reservoir, MergeWithFailedShiftNeverSelectsButCountsConfidence) {
  RsReservoir a = rs_empty(), b = rs_empty();
  rs_update(a, 2.0f, 4.0f, 3.0f, 0.5f);
  rs_finalize(a);
  EXPECT_FALSE(rs_merge(b, a, 4.0f, 0.0f, 1.0f, 0.0f));  // Jacobian 0: failed shift
  EXPECT_EQ(b.w_sum, 0.0f);
  EXPECT_EQ(b.M, 3.0f);
  rs_finalize(b);
  EXPECT_EQ(b.W, 0.0f);
}

TEST(Reservoir, FinalizeGuards) {
  const float inf = std::numeric_limits<float>::infinity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  struct Case { float w_sum, p_hat, W; } cases[] = {
      {1.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, {inf, 1.0f, 0.0f}, {1.0f, nan, 0.0f},
      {nan, 1.0f, 0.0f},  {1.0f, inf, 0.0f},  {3e38f, 1e-10f, 0.0f}, {6.0f, 2.0f, 3.0f},
      {-1.0f, 2.0f, 0.0f}};
  for (const Case& c : cases) {
    RsReservoir r = rs_empty();
    r.w_sum = c.w_sum;
    r.p_hat = c.p_hat;
    rs_finalize(r);
    EXPECT_EQ(r.W, c.W) << "w_sum " << c.w_sum << " p_hat " << c.p_hat;
  }
}

TEST(Reservoir, UpdateIgnoresNonFiniteAndNegativeWeights) {
  RsReservoir r = rs_empty();
  EXPECT_TRUE(rs_update(r, 1.0f, 1.0f, 1.0f, 0.5f));
  EXPECT_FALSE(rs_update(r, std::numeric_limits<float>::quiet_NaN(), 9.0f, 1.0f, 0.0f));
  EXPECT_FALSE(rs_update(r, std::numeric_limits<float>::infinity(), 9.0f, 1.0f, 0.0f));
  EXPECT_FALSE(rs_update(r, -2.0f, 9.0f, 1.0f, 0.0f));
  EXPECT_EQ(r.w_sum, 1.0f);
  EXPECT_EQ(r.p_hat, 1.0f);
  EXPECT_EQ(r.M, 4.0f);
}

TEST(Reservoir, CapConfidence) {
  RsReservoir r = rs_empty();
  r.M = 50.0f;
  rs_cap_confidence(r, 20.0f);
  EXPECT_EQ(r.M, 20.0f);
  rs_cap_confidence(r, 80.0f);
  EXPECT_EQ(r.M, 20.0f);
}

TEST(Reservoir, PackUnpackRoundTrip) {
  RsReservoir r = rs_empty();
  r.w_sum = 12.375f;
  r.p_hat = 0.1f;
  r.W = 123.75f;
  for (float M : {0.0f, 1.0f, 4.0f, 20.5f, 65535.0f, 1.0f / 256.0f, 1234.99609375f}) {
    r.M = M;
    bool dropped = true;
    RsReservoir back = rs_unpack(rs_pack(r), dropped);
    EXPECT_FALSE(dropped);
    EXPECT_EQ(back.w_sum, r.w_sum);
    EXPECT_EQ(back.p_hat, r.p_hat);
    EXPECT_EQ(back.W, r.W);
    EXPECT_EQ(back.M, M);
  }
  r.M = 1e9f;  // saturates
  bool dropped = true;
  EXPECT_EQ(rs_unpack(rs_pack(r), dropped).M, RS_M_MAX);
  r.M = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(rs_unpack(rs_pack(r), dropped).M, 0.0f);
}

TEST(Reservoir, UnpackDropsNonFiniteWeights) {
  const float bad[] = {std::numeric_limits<float>::quiet_NaN(),
                       std::numeric_limits<float>::infinity(),
                       -std::numeric_limits<float>::infinity(), -1.0f};
  int droppedCount = 0;
  for (int field = 0; field < 3; ++field) {
    for (float v : bad) {
      RsReservoir r = rs_empty();
      r.w_sum = 2.0f;
      r.p_hat = 1.0f;
      r.W = 2.0f;
      r.M = 7.0f;
      (field == 0 ? r.w_sum : field == 1 ? r.p_hat : r.W) = v;
      bool dropped = false;
      RsReservoir back = rs_unpack(rs_pack(r), dropped);
      droppedCount += dropped ? 1 : 0;
      EXPECT_TRUE(dropped) << "field " << field << " value " << v;
      EXPECT_EQ(back.w_sum, 0.0f);
      EXPECT_EQ(back.p_hat, 0.0f);
      EXPECT_EQ(back.W, 0.0f);
      EXPECT_EQ(back.M, 7.0f);  // confidence kept so MIS weights stay consistent
    }
  }
  EXPECT_EQ(droppedCount, 12);
}

TEST(Reservoir, IsFinite) {
  EXPECT_TRUE(rs_is_finite(0.0f));
  EXPECT_TRUE(rs_is_finite(-3.4e38f));
  EXPECT_TRUE(rs_is_finite(std::numeric_limits<float>::denorm_min()));
  EXPECT_FALSE(rs_is_finite(std::numeric_limits<float>::infinity()));
  EXPECT_FALSE(rs_is_finite(-std::numeric_limits<float>::infinity()));
  EXPECT_FALSE(rs_is_finite(std::numeric_limits<float>::quiet_NaN()));
}
