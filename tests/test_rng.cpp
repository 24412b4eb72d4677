// Tier (a) of DESIGN §7 for shaders/shared/rng.h: uniformity, independence of streams, pixels,
// frames and consecutive draws, the range of rng_to_float, and determinism. Fixed seeds.
#include "core/stats.h"
#include "support/test_support.h"

#include "shaders/shared/rng.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <vector>

using namespace plume;
using namespace plume::shared;

namespace {

constexpr int kDraws = 1000000;
constexpr int kBins = 100;
// Tests of independence in this file: their chi-squares share a Šidák-corrected level.
constexpr int kIndependenceTests = 8;
// |Pearson correlation| of n independent uniform pairs has standard deviation 1/sqrt(n).
constexpr double kCorrelationSigmas = 5.0;

void expectChi2(const std::vector<double>& counts, const std::string& name, int tests = 1) {
  test::expectChi2(counts, std::vector<double>(counts.size(), kDraws / double(counts.size())), "rng_" + name, name, tests);
}

int bin(float u, int bins) { return std::min(bins - 1, int(u * float(bins))); }

// Draws kDraws pairs and checks their correlation and a 10x10 joint chi-square.
void expectIndependent(const std::function<vec2(int)>& pair, const std::string& name) {
  constexpr int kSide = 10;
  std::vector<double> joint(kSide * kSide, 0.0);
  double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
  for (int i = 0; i < kDraws; ++i) {
    const vec2 p = pair(i);
    joint[size_t(bin(p.x, kSide) * kSide + bin(p.y, kSide))] += 1.0;
    sx += p.x, sy += p.y, sxx += double(p.x) * p.x, syy += double(p.y) * p.y;
    sxy += double(p.x) * p.y;
  }
  const double n = kDraws, cov = sxy / n - sx / n * sy / n;
  const double corr = cov / std::sqrt((sxx / n - sx * sx / n / n) * (syy / n - sy * sy / n / n));
  EXPECT_LT(std::abs(corr), kCorrelationSigmas / std::sqrt(n)) << name;
  expectChi2(joint, name, kIndependenceTests);
}

}  // namespace

TEST(Rng, ToFloatRange) {
  EXPECT_EQ(rng_to_float(0u), 0.0f);
  EXPECT_LT(rng_to_float(0xFFFFFFFFu), 1.0f);
  EXPECT_GT(rng_to_float(0xFFFFFFFFu), 0.9999999f);
  EXPECT_EQ(rng_to_float(0x80000000u), 0.5f);
  RngState r = rng_init(uvec2(0u, 0u), 0u, RNG_STREAM_TEST, 0u);
  for (int i = 0; i < kDraws; ++i) {
    const float u = rng_float(r);
    ASSERT_TRUE(u >= 0.0f && u < 1.0f) << u;
  }
}

TEST(Rng, UniformWithinOneStream) {
  RngState r = rng_init(uvec2(3u, 5u), 7u, RNG_STREAM_TEST, 1u);
  std::vector<double> counts(kBins, 0.0);
  for (int i = 0; i < kDraws; ++i) counts[size_t(bin(rng_float(r), kBins))] += 1.0;
  expectChi2(counts, "one_stream");
}

TEST(Rng, UniformAcrossPixels) {
  // The first draw of each of 1000x1000 pixels: what a pass that draws once per pixel sees.
  std::vector<double> counts(kBins, 0.0);
  for (int i = 0; i < kDraws; ++i) {
    RngState r = rng_init(uvec2(uint(i % 1000), uint(i / 1000)), 0u, RNG_STREAM_CAMERA, 1u);
    counts[size_t(bin(rng_float(r), kBins))] += 1.0;
  }
  expectChi2(counts, "across_pixels");
}

TEST(Rng, AllFourWordsUniform) {
  // rng_float2 uses words x and y; every word of rng_next4 must be uniform on its own.
  RngState r = rng_init(uvec2(8u, 1u), 2u, RNG_STREAM_TEST, 5u);
  std::vector<std::vector<double>> counts(4, std::vector<double>(kBins, 0.0));
  for (int i = 0; i < kDraws; ++i) {
    const uvec4 h = rng_next4(r);
    for (int c = 0; c < 4; ++c) counts[size_t(c)][size_t(bin(rng_to_float(h[c]), kBins))] += 1.0;
  }
  for (int c = 0; c < 4; ++c) expectChi2(counts[size_t(c)], "word" + std::to_string(c), 4);
}

TEST(Rng, StreamsAreIndependent) {
  expectIndependent([](int i) {
    const uvec2 px(uint(i % 1000), uint(i / 1000));
    RngState a = rng_init(px, 0u, RNG_STREAM_CANDIDATES, 1u);
    RngState b = rng_init(px, 0u, RNG_STREAM_SPATIAL, 1u);
    return vec2(rng_float(a), rng_float(b));
  }, "streams");
}

TEST(Rng, NeighbouringPixelsAreIndependent) {
  expectIndependent([](int i) {
    const uvec2 px(uint(i % 1000), uint(i / 1000));
    RngState a = rng_init(px, 0u, RNG_STREAM_PATH, 1u);
    RngState b = rng_init(px + uvec2(1u, 0u), 0u, RNG_STREAM_PATH, 1u);
    return vec2(rng_float(a), rng_float(b));
  }, "pixels");
}

TEST(Rng, ConsecutiveFramesAndSeedsAreIndependent) {
  expectIndependent([](int i) {
    const uvec2 px(uint(i % 1000), uint(i / 1000));
    RngState a = rng_init(px, 4u, RNG_STREAM_PATH, 1u);
    RngState b = rng_init(px, 5u, RNG_STREAM_PATH, 1u);
    return vec2(rng_float(a), rng_float(b));
  }, "frames");
  expectIndependent([](int i) {
    const uvec2 px(uint(i % 1000), uint(i / 1000));
    RngState a = rng_init(px, 0u, RNG_STREAM_PATH, 1u);
    RngState b = rng_init(px, 0u, RNG_STREAM_PATH, 2u);
    return vec2(rng_float(a), rng_float(b));
  }, "seeds");
}

TEST(Rng, ConsecutiveDrawsAreIndependent) {
  RngState r = rng_init(uvec2(17u, 4u), 0u, RNG_STREAM_TEST, 3u);
  expectIndependent([&r](int) {
    const float x = rng_float(r);
    return vec2(x, rng_float(r));
  }, "serial");
}

// The walks' generator (rng_walk_*: xoshiro128+ seeded by one draw of the stream). A tentative
// collision takes two numbers in a row (its optical depth and its u); a walk takes as many pairs
// as it has collisions, the next walk of the path a new state from the stream's next draw.
TEST(Rng, WalkUniformWithinOneWalk) {
  RngState r = rng_init(uvec2(3u, 5u), 7u, RNG_STREAM_PATH, 1u);
  RngWalk g = rng_walk_init(r);
  std::vector<double> counts(kBins, 0.0);
  for (int i = 0; i < kDraws; ++i) counts[size_t(bin(rng_to_float(rng_walk_next(g)), kBins))] += 1.0;
  expectChi2(counts, "walk_one");
}

TEST(Rng, WalkUniformAtEachDrawAcrossWalks) {
  // Draw k of the walks of many paths (short walks read only their first few).
  RngState r = rng_init(uvec2(9u, 2u), 1u, RNG_STREAM_PATH, 4u);
  std::vector<std::vector<double>> counts(4, std::vector<double>(kBins, 0.0));
  for (int i = 0; i < kDraws; ++i) {
    RngWalk g = rng_walk_init(r);
    for (int k = 0; k < 4; ++k) counts[size_t(k)][size_t(bin(rng_to_float(rng_walk_next(g)), kBins))] += 1.0;
  }
  for (int k = 0; k < 4; ++k) expectChi2(counts[size_t(k)], "walk_draw" + std::to_string(k), 4);
}

TEST(Rng, WalkPairsAreIndependent) {
  // A collision's two numbers: the first pair of each walk, and pairs deep in one walk.
  RngState r = rng_init(uvec2(1u, 8u), 0u, RNG_STREAM_PATH, 2u);
  expectIndependent([&r](int) {
    RngWalk g = rng_walk_init(r);
    const float x = rng_to_float(rng_walk_next(g));
    return vec2(x, rng_to_float(rng_walk_next(g)));
  }, "walk_first_pair");
  RngWalk deep = rng_walk_init(r);
  expectIndependent([&deep](int) {
    const float x = rng_to_float(rng_walk_next(deep));
    return vec2(x, rng_to_float(rng_walk_next(deep)));
  }, "walk_serial");
}

TEST(Rng, ConsecutiveWalksAreIndependent) {
  // The first number of a path's walk and of its next walk (the stream's consecutive draws), and of
  // neighbouring pixels' walks.
  RngState r = rng_init(uvec2(4u, 4u), 3u, RNG_STREAM_PATH, 6u);
  expectIndependent([&r](int i) {
    RngWalk a = rng_walk_init(r);
    RngWalk b = rng_walk_init(r);
    if (i % 2 == 1) rng_walk_next(b);  // (a shorter and a longer first walk alike)
    return vec2(rng_to_float(rng_walk_next(a)), rng_to_float(rng_walk_next(b)));
  }, "walk_next_walk");
}

TEST(Rng, Deterministic) {
  RngState a = rng_init(uvec2(5u, 6u), 7u, RNG_STREAM_SHADING, 8u);
  RngState b = rng_init(uvec2(5u, 6u), 7u, RNG_STREAM_SHADING, 8u);
  for (int i = 0; i < 1000; ++i) ASSERT_EQ(rng_uint(a), rng_uint(b));
  RngState c = rng_init(uvec2(5u, 6u), 7u, RNG_STREAM_SHADING, 9u);
  int same = 0;
  for (int i = 0; i < 1000; ++i) same += rng_uint(a) == rng_uint(c) ? 1 : 0;
  EXPECT_LT(same, 3);
}

TEST(Rng, UniformityTestCanFail) {
  // A generator with a 5% bias towards small values must be rejected by the same check.
  RngState r = rng_init(uvec2(3u, 5u), 7u, RNG_STREAM_TEST, 1u);
  std::vector<double> counts(kBins, 0.0);
  for (int i = 0; i < kDraws; ++i) {
    const float u = rng_float(r);
    counts[size_t(bin(u * (0.95f + 0.05f * u), kBins))] += 1.0;
  }
  std::vector<double> expected(kBins, kDraws / double(kBins));
  EXPECT_FALSE(chi2Test(counts, expected).pass);
}
