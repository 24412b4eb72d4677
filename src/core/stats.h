// Statistics for tests and measurements (DESIGN §6, §7): Pearson chi-square goodness of fit,
// normal p-values, relMSE, and per-pixel Z-tests between images with a Šidák correction.
// The failed test's images as EXR files: io/failure_images.h.
#pragma once

#include "core/image.h"

#include <glm/vec3.hpp>

#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace plume {

// --- Pearson chi-square goodness of fit (in the manner of pbrt-v4's tests) ----------------
// Significance level of one test (pbrt's CHI2_SLEVEL). With several tests in one program,
// pass their number: the per-test level is Šidák-corrected, 1 - (1 - level)^(1/count).
constexpr double kChi2SignificanceLevel = 0.01;
// Bins expected to hold fewer samples than this are pooled (pbrt's CHI2_MINFREQ).
constexpr double kChi2MinExpectedFrequency = 5.0;
// Observed samples tolerated in bins of expected count 0, as a fraction of all samples
// (floating-point round-off at a domain's edge); more fails the test outright.
constexpr double kChi2ZeroBinTolerance = 1e-5;

struct Chi2Result {
  bool pass = false;
  double statistic = 0.0;   // Σ (O - E)^2 / E over the bins after pooling
  int dof = 0;              // bins after pooling - 1
  double pValue = 0.0;      // Q(dof/2, statistic/2)
  double level = 0.0;       // per-test significance level after the Šidák correction
  int pooledBins = 0;       // bins merged into the pooled bin
  std::string message;      // why it failed (empty when it passed)
  std::string table;        // summary and the bins that contribute most, for test output
};

// observed[i] and expected[i] are counts (expected = probability of bin i * sample count).
Chi2Result chi2Test(std::span<const double> observed, std::span<const double> expected,
                    double level = kChi2SignificanceLevel, int testCount = 1);

// Writes <dir>/<name>.txt with the result's table; for tests on failure. Returns the path.
std::string writeChi2Report(const std::string& dir, const std::string& name, const Chi2Result& r);

// Regularised incomplete gamma functions P(a, x) and Q(a, x) = 1 - P (a > 0, x >= 0):
// series for x < a + 1, Lentz continued fraction otherwise (Numerical Recipes §6.2).
double regularizedGammaP(double a, double x);
double regularizedGammaQ(double a, double x);
// Survival function of the chi-square distribution: P(X >= statistic) with `dof` degrees.
double chi2SurvivalFunction(double statistic, int dof);

// --- Normal distribution -----------------------------------------------------------------
double normalCdf(double z);
double twoSidedPValue(double z);  // P(|Z| >= |z|) for a standard normal Z
// Šidák per-test level for `count` tests at family-wise level alpha: 1 - (1 - alpha)^(1/count).
double sidakLevel(double alpha, double count);

// --- Errors between images (DESIGN §6) --------------------------------------------------
// One channel's term, (x - r)^2 / (r^2 + 1e-2).
double relMseTerm(float x, float reference);
// mean over pixels and channels of relMseTerm; x, r: equal-length rgb arrays.
double relMse(std::span<const float> x, std::span<const float> reference);
double relMse(const Image& x, const Image& reference);  // throws InputError on a size mismatch
// Where relMSE sits: each pixel's share of it (the sum of its three channels' terms over the
// image's sum), the n largest, largest first. Throws InputError on a size mismatch.
struct PixelError {
  int x = 0, y = 0;
  double share = 0.0;  // of the image's relMSE, in [0, 1]
};
std::vector<PixelError> worstPixels(const Image& x, const Image& reference, int n);
// The share of relMSE held by the largest `fraction` of the pixels (at least one pixel).
double shareOfWorst(const Image& x, const Image& reference, double fraction);
// mean(a) / mean(b) over all pixels and channels: 1 when both means are 0, inf or NaN when
// only mean(b) is 0.
double meanRatio(std::span<const float> a, std::span<const float> b);

// --- Per-pixel Z-tests -------------------------------------------------------------------
constexpr double kZTestAlpha = 0.01;  // family-wise level over all pixels and channels
// Relative precision floor of every channel test: (kZTestRelativePrecision * max(|a|, |b|))^2 is
// added to the variance. Two correct renderers differ by float and half-texel rounding (the
// bake's storage error is up to 2.4e-4 of the density), and a Monte Carlo variance estimate of
// 0 only means no rare event was sampled (a pixel whose reference rays all missed a faint wisp
// that the other renderer grazed): neither may turn the test into an exact-equality check.
constexpr double kZTestRelativePrecision = 1e-4;
// And an absolute one: a difference below the smallest normal float is rounding too. Denormal
// radiance (session 28: a pixel of the Blender fire read 1.68e-44 in red on the GPU, exactly 0 in
// the reference) is flushed to 0 by devices that flush denormals (Vulkan allows it) and its square
// underflows in the float variance accumulators, so a denormal against an exact 0 with no
// variance is no evidence of a bias (without this floor such a pixel read z = 1e4).
constexpr double kZTestAbsolutePrecision = 1.17549435e-38;  // FLT_MIN

struct ZTestResult {
  bool pass = true;
  double alpha = kZTestAlpha;  // family-wise level
  double perTestLevel = 0.0;   // Šidák level for each of the 3 * width * height channel tests
  size_t tests = 0;            // channel tests (3 per pixel)
  size_t failingPixels = 0;    // pixels with at least one failing channel
  double failingFraction = 0.0;
  double worstZ = 0.0;         // signed z of the largest |z| (inf for an exact mismatch or NaN)
  int worstX = -1, worstY = -1, worstChannel = -1;
  double relMse = 0.0;         // of a against b
  double meanRatio = 1.0;      // mean(a) / mean(b)
  int width = 0, height = 0;
  std::vector<float> z;        // per channel z-scores, 3 * width * height (0 where exact match)
  std::string summary() const; // several lines, for test output and `plume compare`
};

// The tests treat z as standard normal, which needs well-estimated variances: with variances
// estimated from n samples z follows Student's t with n - 1 degrees, whose tails fail the
// Šidák threshold (about 5 sigma for 10^4 tests) far too often for small n (use n >= ~100).
// Two estimates with variances of their means: z = (a - b) / sqrt(va + vb) per channel,
// each compared at the Šidák level. Throws InputError on a size mismatch or a missing variance.
ZTestResult zTest(const Image& a, const Image& b, double alpha = kZTestAlpha);
// Against exact values (an analytic image, rgb of 3 * width * height floats, or a constant):
// the variance comes from `a` only.
ZTestResult zTestAgainst(const Image& a, std::span<const float> exactRgb,
                         double alpha = kZTestAlpha);
ZTestResult zTestAgainst(const Image& a, glm::vec3 exact, double alpha = kZTestAlpha);

// The z-scores as an image (R,G,B = z per channel) for viewing beside the inputs.
Image zScoreImage(const ZTestResult& result);

// Writes <dir>/<name>_summary.txt (the result's summary); returns its path. For tests on failure
// (dir: build/test-output/<test>, see tests/support).
std::string writeFailureReport(const std::string& dir, const std::string& name,
                               const ZTestResult& result);

}  // namespace plume
