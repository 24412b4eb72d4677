// `plume compare` end to end: exit codes 0 (Z-test passes), 1 (fails), 2 (bad input: missing
// file, size mismatch, no variance channels, bad --alpha) and what it prints.
#include "io/image.h"
#include "support/test_support.h"

#include "shaders/shared/rng.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

using namespace plume;

namespace {

// A noisy estimate (mean of kN samples with uniform noise, and its variance) of a smooth
// image; `bias` standard errors are added in the top-left quarter. kN must be large: with an
// estimated variance z follows Student's t with kN - 1 degrees, whose tails (16 samples: t_15)
// fail a normal-theory test at the Šidák level.
constexpr int kN = 256;
// exact: the smooth image itself, without variance channels.
Image noisy(int w, int h, uint32_t seed, double bias = 0.0, bool withVariance = true,
            bool exact = false) {
  Image img;
  img.width = w;
  img.height = h;
  img.rgb.assign(size_t(3 * w * h), 0.0f);
  if (withVariance) img.var.assign(img.rgb.size(), 0.0f);
  shared::RngState rng = shared::rng_init(glm::uvec2(seed, 0u), 0u, shared::RNG_STREAM_TEST, 51u);
  for (size_t i = 0; i < img.rgb.size(); ++i) {
    const size_t p = i / 3;
    const int x = int(p % size_t(w)), y = int(p / size_t(w));
    const double truth = 1.0 + 0.5 * std::sin(0.3 * x + 0.2 * y + double(i % 3));
    double sum = 0.0, sumSq = 0.0;
    for (int s = 0; s < kN; ++s) {
      const double v = truth * (0.6 + 0.8 * shared::rng_float(rng));
      sum += v;
      sumSq += v * v;
    }
    if (exact) sum = kN * truth, sumSq = kN * truth * truth;
    const double mean = sum / kN, varMean = (sumSq - kN * mean * mean) / (kN - 1) / kN;
    const bool region = x < w / 2 && y < h / 2;
    img.rgb[i] = float(mean + (region ? bias * std::sqrt(varMean) : 0.0));
    if (withVariance) img.var[i] = float(varMean);
  }
  return img;
}

class Compare : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = test::outputDir("compare");
    writeExr(path("a.exr"), noisy(32, 24, 1));
    writeExr(path("b.exr"), noisy(32, 24, 2));
    writeExr(path("biased.exr"), noisy(32, 24, 3, 8.0));
    writeExr(path("novar.exr"), noisy(32, 24, 4, 0.0, false));
    writeExr(path("small.exr"), noisy(16, 24, 5));
    writeExr(path("truth.exr"), noisy(32, 24, 0, 0.0, false, true));
  }
  static std::string path(const std::string& name) { return dir_ + "/" + name; }
  static std::string dir_;
};
std::string Compare::dir_;

}  // namespace

TEST_F(Compare, PassesForTwoEstimatesOfTheSameImage) {
  test::RunResult r = test::runPlume({"compare", path("a.exr"), path("b.exr")});
  EXPECT_EQ(r.exitCode, 0) << r.output;
  for (const char* s : {"relMSE", "mean ratio", "failing", "worst pixel", "pass"}) {
    EXPECT_NE(r.output.find(s), std::string::npos) << s << "\n" << r.output;
  }
}

TEST_F(Compare, WorstListsWhereTheErrorSits) {
  // The biased image's error is in its top-left quarter: every listed pixel lies there.
  test::RunResult r = test::runPlume({"compare", path("biased.exr"), path("b.exr"), "--worst", "5"});
  EXPECT_EQ(r.exitCode, 1) << r.output;
  EXPECT_NE(r.output.find("worst 1% of pixels hold"), std::string::npos) << r.output;
  int listed = 0;
  for (size_t at = r.output.find("\n  ("); at != std::string::npos; at = r.output.find("\n  (", at + 1)) {
    int x = -1, y = -1;
    ASSERT_EQ(std::sscanf(r.output.c_str() + at, "\n  (%d, %d)", &x, &y), 2) << r.output;
    EXPECT_LT(x, 16) << r.output;
    EXPECT_LT(y, 12) << r.output;
    ++listed;
  }
  EXPECT_EQ(listed, 5) << r.output;
  EXPECT_EQ(test::runPlume({"compare", path("a.exr"), path("b.exr"), "--worst", "-1"}).exitCode, 2);
}

TEST_F(Compare, FailsForABiasedImage) {
  test::RunResult r = test::runPlume({"compare", path("biased.exr"), path("b.exr")});
  EXPECT_EQ(r.exitCode, 1) << r.output;
  EXPECT_NE(r.output.find("FAIL"), std::string::npos) << r.output;
}

TEST_F(Compare, AlphaChangesTheThreshold) {
  // alpha so close to 1 that the per-test level is large: even unbiased noise fails.
  test::RunResult r =
      test::runPlume({"compare", path("a.exr"), path("b.exr"), "--alpha", "0.999999"});
  EXPECT_EQ(r.exitCode, 1) << r.output;
  for (const char* bad : {"0", "1", "1.5", "-0.1", "abc"}) {
    r = test::runPlume({"compare", path("a.exr"), path("b.exr"), "--alpha", bad});
    EXPECT_EQ(r.exitCode, 2) << bad << "\n" << r.output;
  }
}

TEST_F(Compare, MissingFileIsBadInput) {
  test::RunResult r = test::runPlume({"compare", path("a.exr"), path("nonexistent.exr")});
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_NE(r.output.find("nonexistent.exr"), std::string::npos) << r.output;
  EXPECT_EQ(test::runPlume({"compare", path("a.exr")}).exitCode, 2);
}

TEST_F(Compare, SizeMismatchIsBadInput) {
  test::RunResult r = test::runPlume({"compare", path("a.exr"), path("small.exr")});
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_NE(r.output.find("32x24"), std::string::npos) << r.output;
}

TEST_F(Compare, NoVarianceReportsErrorsButCannotTest) {
  test::RunResult r = test::runPlume({"compare", path("a.exr"), path("novar.exr")});
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_NE(r.output.find("relMSE"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("mean ratio"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("cannot run"), std::string::npos) << r.output;
  // --exact-b: b is exact (an analytic image), only a's variance is needed.
  r = test::runPlume({"compare", path("a.exr"), path("truth.exr"), "--exact-b"});
  EXPECT_EQ(r.exitCode, 0) << r.output;
  r = test::runPlume({"compare", path("biased.exr"), path("truth.exr"), "--exact-b"});
  EXPECT_EQ(r.exitCode, 1) << r.output;
  r = test::runPlume({"compare", path("novar.exr"), path("a.exr"), "--exact-b"});
  EXPECT_EQ(r.exitCode, 2) << r.output;  // a still needs variances
}
