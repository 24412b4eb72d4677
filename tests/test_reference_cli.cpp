// `plume reference` end to end on the bundled smoke: a 128² frame at 256 spp completes, its
// variance image agrees with the spread between two independent seeds, the same seed gives the
// same pixels, and the header carries the run's metadata.
#include "io/image.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace plume;

namespace {

Image renderSeed(const std::string& dir, int seed) {
  const std::string out = dir + "/seed" + std::to_string(seed) + ".exr";
  test::RunResult r = test::runPlume({"reference", test::sourcePath("volumes/smoke/smoke.json"), "-o", out,
                                      "--frames", "12", "--spp", "256", "--seed", std::to_string(seed), "-q"});
  EXPECT_EQ(r.exitCode, 0) << r.output;
  return readExr(out);
}

}  // namespace

TEST(ReferenceCli, VarianceImageMatchesSpreadBetweenSeedsOnBundledSmoke) {
  const std::string dir = test::outputDir("reference_cli");
  Image a = renderSeed(dir, 1);
  Image b = renderSeed(dir, 2);
  ASSERT_EQ(a.width, 128);
  ASSERT_TRUE(a.hasVariance() && b.hasVariance());
  // E[(a - b)^2] = var(a) + var(b) per pixel and channel; compare the sums.
  double spread = 0, predicted = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i) {
    spread += double(a.rgb[i] - b.rgb[i]) * (a.rgb[i] - b.rgb[i]);
    predicted += double(a.var[i]) + b.var[i];
  }
  ASSERT_GT(predicted, 0);
  EXPECT_NEAR(spread / predicted, 1.0, 0.05) << "spread " << spread << " predicted " << predicted;
  EXPECT_NE(a.rgb, b.rgb);
  EXPECT_EQ(a.meta["spp"], "256");
  EXPECT_EQ(a.meta["seed"], "1");
  EXPECT_EQ(a.meta["frame"], "12");
  EXPECT_EQ(a.meta["mode"], "reference");
  EXPECT_EQ(a.meta["tracking_truncated"], "0");
  EXPECT_FALSE(a.meta["wall_time_s"].empty());
  EXPECT_EQ(renderSeed(dir, 1).rgb, a.rgb) << "same seed, same pixels";
}
