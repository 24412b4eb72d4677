// Blackbody emission colour (DESIGN §2, core/blackbody.h): the CIE data and the integral against
// independently published chromaticities of the Planckian locus, the normalisation, the hue, and
// the GPU's table (shaders/shared/blackbody.h) against the exact function.
#include "core/blackbody.h"

#include <gtest/gtest.h>

#include <cmath>

#define BB_TABLE(i) glm::vec3(bbTable[i])
namespace {
std::vector<glm::vec4> bbTable;
}
#include "shaders/shared/blackbody.h"

using namespace plume;

namespace {

glm::dvec2 chromaticity(const glm::dvec3& xyz) { return glm::dvec2(xyz.x, xyz.y) / (xyz.x + xyz.y + xyz.z); }

TEST(Blackbody, CieTableIntegratesToTheStandardValue) {
  // ∫ȳ of the CIE 1931 2° observer is 106.856895 (1 nm table); the 5 nm table interpolated
  // linearly must land within 0.05 %.
  EXPECT_NEAR(cieYIntegral(), 106.856895, 0.05);
}

TEST(Blackbody, CieIlluminantAChromaticity) {
  // CIE illuminant A (CIE 15:2004) is Planck's law with c2 = 1.435e-2 m·K at 2848 K,
  // chromaticity (0.44757, 0.40745); with today's c2 = 1.438777e-2 the same spectrum has
  // T = 2848 * c2' / c2 (about 2856 K).
  const double t = 2848.0 * 1.438777e-2 / 1.435e-2;
  const glm::dvec2 xy = chromaticity(blackbodyXyz(t));
  EXPECT_NEAR(xy.x, 0.44757, 3e-4);
  EXPECT_NEAR(xy.y, 0.40745, 3e-4);
}

TEST(Blackbody, PlanckianLocusChromaticities) {
  // Published Planckian-locus chromaticities (CIE 1931 2°), to their 4 printed digits.
  struct Point {
    double kelvin, x, y;
  };
  const Point locus[] = {{1000, 0.6528, 0.3444}, {2000, 0.5267, 0.4133}, {3000, 0.4369, 0.4041},
                         {4000, 0.3805, 0.3768}, {5000, 0.3451, 0.3516}, {6500, 0.3135, 0.3236},
                         {10000, 0.2807, 0.2884}};
  for (const Point& p : locus) {
    const glm::dvec2 xy = chromaticity(blackbodyXyz(p.kelvin));
    EXPECT_NEAR(xy.x, p.x, 1e-3) << p.kelvin << " K";
    EXPECT_NEAR(xy.y, p.y, 1e-3) << p.kelvin << " K";
  }
}

TEST(Blackbody, NormalisedByItsPeak) {
  for (double t : {500.0, 1000.0, 3000.0, 5800.0, 10000.0, 40000.0}) {
    // The spectrum divided by its maximum is <= 1 at every wavelength, so Y <= ∫ȳ/∫ȳ = 1, and the
    // maximum is at Wien's peak.
    const double peak = planck(kWienDisplacement / t, t);
    for (double f : {0.9, 0.99, 1.01, 1.1}) EXPECT_LE(planck(f * kWienDisplacement / t, t), peak) << t;
    const glm::dvec3 xyz = blackbodyXyz(t);
    EXPECT_GT(xyz.y, 0.0) << t;
    EXPECT_LE(xyz.y, 1.0) << t;
  }
  // The peak falls in the visible near 5000-6000 K, where Y approaches its bound.
  EXPECT_GT(blackbodyXyz(5800).y, 0.7);
  EXPECT_EQ(blackbodyRgb(100.0), glm::dvec3(0.0));
  EXPECT_EQ(blackbodyRgb(50.0), glm::dvec3(0.0));
}

TEST(Blackbody, HueRunsFromRedToWhiteToBlue) {
  const glm::dvec3 red = blackbodyRgb(1000);
  EXPECT_GT(red.x, 0.0);
  EXPECT_GT(red.x, 10.0 * red.y);
  EXPECT_EQ(red.z, 0.0);  // outside Rec.709: clamped
  const glm::dvec3 white = blackbodyRgb(6500);
  const double lo = std::min({white.x, white.y, white.z}), hi = std::max({white.x, white.y, white.z});
  EXPECT_LT(hi / lo, 1.15) << white.x << " " << white.y << " " << white.z;
  EXPECT_GT(blackbodyRgb(15000).z, blackbodyRgb(15000).x);
  // Monotone: red over blue falls as T rises.
  double prev = 1e300;
  for (double t = 2000; t <= 20000; t += 250) {
    const glm::dvec3 c = blackbodyRgb(t);
    const double ratio = c.x / c.z;
    EXPECT_LT(ratio, prev) << t;
    prev = ratio;
  }
}

TEST(Blackbody, DeviceTableMatchesTheIntegral) {
  bbTable = blackbodyTable();
  ASSERT_EQ(bbTable.size(), size_t(shared::BB_TABLE_SIZE));
  double worst = 0.0, worstT = 0.0;
  // Between the entries (the worst case for linear interpolation) and on them, 1000-10000 K.
  for (double t = 1000.0; t <= 10000.0; t *= 1.000731) {
    const glm::dvec3 exact = blackbodyRgb(t);
    const glm::dvec3 table = glm::dvec3(shared::bb_lookup(float(t)));
    const double scale = std::max({exact.x, exact.y, exact.z});
    const double err = glm::length(table - exact) / scale;
    if (err > worst) worst = err, worstT = t;
  }
  EXPECT_LT(worst, 1e-3) << "at " << worstT << " K";
  // Beyond the table: the Rayleigh-Jeans tail, continuous at the end and close to the integral.
  const glm::dvec3 far = blackbodyRgb(4e6), farTable = glm::dvec3(shared::bb_lookup(4e6f));
  EXPECT_LT(glm::length(farTable - far) / std::max({far.x, far.y, far.z}), 2e-2);
  EXPECT_EQ(glm::dvec3(shared::bb_lookup(100.0f)), glm::dvec3(0.0));
  EXPECT_EQ(glm::dvec3(shared::bb_lookup(std::nanf(""))), glm::dvec3(0.0));
}

}  // namespace
