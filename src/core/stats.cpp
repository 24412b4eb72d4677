#include "core/stats.h"

#include "core/error.h"
#include "core/log.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <numeric>

namespace plume {

// --- Incomplete gamma ----------------------------------------------------------------------
namespace {
constexpr int kGammaMaxIterations = 10000;
constexpr double kGammaEps = 1e-15;
constexpr double kGammaTiny = 1e-300;

// P(a, x) by its power series: e^{-x} x^a / Γ(a+1) Σ_n x^n / ((a+1)...(a+n)).
double gammaPSeries(double a, double x) {
  double term = 1.0 / a, sum = term;
  for (int n = 1; n < kGammaMaxIterations; ++n) {
    term *= x / (a + n);
    sum += term;
    if (std::abs(term) < std::abs(sum) * kGammaEps) break;
  }
  return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

// Q(a, x) by its continued fraction, evaluated with the modified Lentz method.
double gammaQContinuedFraction(double a, double x) {
  double b = x + 1.0 - a, c = 1.0 / kGammaTiny, d = 1.0 / b, h = d;
  for (int i = 1; i < kGammaMaxIterations; ++i) {
    double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kGammaTiny) d = kGammaTiny;
    c = b + an / c;
    if (std::abs(c) < kGammaTiny) c = kGammaTiny;
    d = 1.0 / d;
    double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < kGammaEps) break;
  }
  return std::exp(-x + a * std::log(x) - std::lgamma(a)) * h;
}
}  // namespace

double regularizedGammaP(double a, double x) {
  PLUME_CHECK(a > 0.0 && x >= 0.0);
  if (x == 0.0) return 0.0;
  return x < a + 1.0 ? gammaPSeries(a, x) : 1.0 - gammaQContinuedFraction(a, x);
}

double regularizedGammaQ(double a, double x) {
  PLUME_CHECK(a > 0.0 && x >= 0.0);
  if (x == 0.0) return 1.0;
  return x < a + 1.0 ? 1.0 - gammaPSeries(a, x) : gammaQContinuedFraction(a, x);
}

double chi2SurvivalFunction(double statistic, int dof) {
  return regularizedGammaQ(0.5 * dof, std::max(0.0, 0.5 * statistic));
}

// --- Normal distribution ------------------------------------------------------------------
double normalCdf(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }

double twoSidedPValue(double z) { return std::erfc(std::abs(z) / std::sqrt(2.0)); }

double sidakLevel(double alpha, double count) {
  PLUME_CHECK(alpha > 0.0 && alpha < 1.0 && count >= 1.0);
  return -std::expm1(std::log1p(-alpha) / count);  // accurate for tiny results
}

// --- Chi-square ------------------------------------------------------------------------------
namespace {
struct Chi2Bin {
  size_t index;
  double observed, expected, contribution;
};

std::string chi2Table(const Chi2Result& r, std::vector<Chi2Bin> bins, double samples) {
  std::string t = strf("chi-square: statistic %.2f, dof %d, p-value %.3g, level %.3g, "
                       "%zu bins (%d pooled), %.0f samples\n",
                       r.statistic, r.dof, r.pValue, r.level, bins.size(), r.pooledBins, samples);
  std::sort(bins.begin(), bins.end(),
            [](const Chi2Bin& x, const Chi2Bin& y) { return x.contribution > y.contribution; });
  t += "   bin      observed      expected   (O-E)^2/E\n";
  for (size_t i = 0; i < std::min<size_t>(bins.size(), 20); ++i) {
    const Chi2Bin& b = bins[i];
    t += strf("%6zu  %12.1f  %12.1f  %10.2f\n", b.index, b.observed, b.expected, b.contribution);
  }
  return t;
}
}  // namespace

Chi2Result chi2Test(std::span<const double> observed, std::span<const double> expected,
                    double level, int testCount) {
  PLUME_CHECK(observed.size() == expected.size());
  Chi2Result r;
  r.level = sidakLevel(level, testCount);
  const double samples = std::accumulate(observed.begin(), observed.end(), 0.0);
  std::vector<Chi2Bin> bins;
  for (size_t i = 0; i < observed.size(); ++i) bins.push_back({i, observed[i], expected[i], 0.0});
  // Pool the bins with small expected counts, smallest first, until the pool is large enough
  // (pbrt-v4's chi2test); bins with expected count 0 must stay (almost) empty.
  std::vector<Chi2Bin> sorted = bins;
  std::stable_sort(sorted.begin(), sorted.end(),
                   [](const Chi2Bin& x, const Chi2Bin& y) { return x.expected < y.expected; });
  double pooledO = 0.0, pooledE = 0.0, zeroO = 0.0;
  for (const Chi2Bin& b : sorted) {
    if (b.expected <= 0.0) {
      zeroO += b.observed;
    } else if (b.expected < kChi2MinExpectedFrequency ||
               (pooledE > 0.0 && pooledE < kChi2MinExpectedFrequency)) {
      pooledO += b.observed;
      pooledE += b.expected;
      ++r.pooledBins;
    } else {
      const double d = b.observed - b.expected;
      bins[b.index].contribution = d * d / b.expected;
      r.statistic += bins[b.index].contribution;
      ++r.dof;
    }
  }
  if (pooledE > 0.0) {
    const double d = pooledO - pooledE;
    r.statistic += d * d / pooledE;
    ++r.dof;
  }
  r.dof -= 1;
  if (zeroO > kChi2ZeroBinTolerance * samples) {
    r.message = strf("%.0f samples fell in bins of expected count 0", zeroO);
  } else if (r.dof < 1) {
    r.message = "fewer than two bins after pooling: the test cannot run";
  } else {
    r.pValue = chi2SurvivalFunction(r.statistic, r.dof);
    r.pass = r.pValue >= r.level;
    if (!r.pass) r.message = strf("p-value %.3g below the level %.3g", r.pValue, r.level);
  }
  r.table = (r.message.empty() ? std::string() : "FAILED: " + r.message + "\n") +
            chi2Table(r, std::move(bins), samples);
  return r;
}

// --- relMSE and mean ratio ----------------------------------------------------------------
double relMseTerm(float x, float reference) {
  const double d = double(x) - reference, r = reference;
  return d * d / (r * r + 1e-2);
}

double relMse(std::span<const float> x, std::span<const float> reference) {
  PLUME_CHECK(x.size() == reference.size());
  if (x.empty()) return 0.0;
  double sum = 0.0;
  for (size_t i = 0; i < x.size(); ++i) sum += relMseTerm(x[i], reference[i]);
  return sum / double(x.size());
}

namespace {
void checkSameSize(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height) {
    throw InputError(strf("image sizes differ: %dx%d and %dx%d", a.width, a.height, b.width,
                          b.height));
  }
}
}  // namespace

double relMse(const Image& x, const Image& reference) {
  checkSameSize(x, reference);
  return relMse(x.rgb, reference.rgb);
}

namespace {
// Each pixel's relMSE terms summed over its channels, and their total.
std::vector<double> pixelTerms(const Image& x, const Image& reference, double& total) {
  checkSameSize(x, reference);
  std::vector<double> terms(size_t(x.width) * size_t(x.height), 0.0);
  total = 0.0;
  for (size_t i = 0; i < x.rgb.size(); ++i) {
    const double t = relMseTerm(x.rgb[i], reference.rgb[i]);
    terms[i / 3] += t;
    total += t;
  }
  return terms;
}
}  // namespace

std::vector<PixelError> worstPixels(const Image& x, const Image& reference, int n) {
  double total = 0.0;
  const std::vector<double> terms = pixelTerms(x, reference, total);
  std::vector<size_t> order(terms.size());
  std::iota(order.begin(), order.end(), size_t(0));
  const size_t k = std::min(order.size(), size_t(std::max(n, 0)));
  std::partial_sort(order.begin(), order.begin() + ptrdiff_t(k), order.end(),
                    [&](size_t a, size_t b) { return terms[a] > terms[b] || (terms[a] == terms[b] && a < b); });
  std::vector<PixelError> out;
  for (size_t j = 0; j < k; ++j) {
    const size_t p = order[j];
    out.push_back({int(p % size_t(x.width)), int(p / size_t(x.width)), total > 0.0 ? terms[p] / total : 0.0});
  }
  return out;
}

double shareOfWorst(const Image& x, const Image& reference, double fraction) {
  double total = 0.0;
  std::vector<double> terms = pixelTerms(x, reference, total);
  if (terms.empty() || total <= 0.0) return 0.0;
  const size_t k = std::clamp(size_t(std::ceil(fraction * double(terms.size()))), size_t(1), terms.size());
  std::nth_element(terms.begin(), terms.begin() + ptrdiff_t(k - 1), terms.end(), std::greater<double>());
  return std::accumulate(terms.begin(), terms.begin() + ptrdiff_t(k), 0.0) / total;
}

double meanRatio(std::span<const float> a, std::span<const float> b) {
  const double sa = std::accumulate(a.begin(), a.end(), 0.0);
  const double sb = std::accumulate(b.begin(), b.end(), 0.0);
  if (sa == 0.0 && sb == 0.0) return 1.0;
  return (sa / double(a.size())) / (sb / double(b.size()));
}

// --- Z-tests ---------------------------------------------------------------------------------
namespace {
// z for one channel test (finite: the precision floors), +inf for a non-finite input.
double channelZ(double a, double b, double variance) {
  if (!std::isfinite(a) || !std::isfinite(b) || !std::isfinite(variance) || variance < 0.0) {
    return std::numeric_limits<double>::infinity();
  }
  const double floor =
      std::max(kZTestRelativePrecision * std::max(std::abs(a), std::abs(b)), kZTestAbsolutePrecision);
  variance += floor * floor;  // > 0: the absolute floor
  return (a - b) / std::sqrt(variance);
}

// The shared core: bVar may be empty (exact b).
ZTestResult zTestArrays(int width, int height, std::span<const float> a,
                        std::span<const float> aVar, std::span<const float> b,
                        std::span<const float> bVar, double alpha) {
  ZTestResult r;
  r.width = width;
  r.height = height;
  r.alpha = alpha;
  r.tests = a.size();
  r.perTestLevel = sidakLevel(alpha, double(std::max<size_t>(r.tests, 1)));
  r.z.assign(a.size(), 0.0f);
  double worst = -1.0;
  for (size_t p = 0; p < a.size() / 3; ++p) {
    bool pixelFails = false;
    for (int c = 0; c < 3; ++c) {
      const size_t i = 3 * p + c;
      const double var = double(aVar[i]) + (bVar.empty() ? 0.0 : double(bVar[i]));
      const double z = channelZ(a[i], b[i], var);
      r.z[i] = float(z);
      pixelFails |= twoSidedPValue(z) < r.perTestLevel;
      if (std::abs(z) > worst) {
        worst = std::abs(z);
        r.worstZ = z;
        r.worstX = int(p % size_t(width));
        r.worstY = int(p / size_t(width));
        r.worstChannel = c;
      }
    }
    r.failingPixels += pixelFails ? 1 : 0;
  }
  const size_t pixels = a.size() / 3;
  r.failingFraction = pixels ? double(r.failingPixels) / double(pixels) : 0.0;
  r.pass = r.failingPixels == 0;
  r.relMse = relMse(a, b);
  r.meanRatio = meanRatio(a, b);
  return r;
}

void requireVariance(const Image& image, const char* which) {
  if (!image.hasVariance()) {
    throw InputError(strf("%s image has no variance channels (var.R, var.G, var.B): the "
                          "Z-test cannot run", which));
  }
}
}  // namespace

ZTestResult zTest(const Image& a, const Image& b, double alpha) {
  checkSameSize(a, b);
  requireVariance(a, "first");
  requireVariance(b, "second");
  return zTestArrays(a.width, a.height, a.rgb, a.var, b.rgb, b.var, alpha);
}

ZTestResult zTestAgainst(const Image& a, std::span<const float> exactRgb, double alpha) {
  requireVariance(a, "first");
  if (exactRgb.size() != a.rgb.size()) {
    throw InputError(strf("exact values: %zu floats for a %dx%d image", exactRgb.size(),
                          a.width, a.height));
  }
  return zTestArrays(a.width, a.height, a.rgb, a.var, exactRgb, {}, alpha);
}

ZTestResult zTestAgainst(const Image& a, glm::vec3 exact, double alpha) {
  std::vector<float> rgb(a.rgb.size());
  for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = exact[int(i % 3)];
  return zTestAgainst(a, rgb, alpha);
}

std::string ZTestResult::summary() const {
  static const char* kChannel[3] = {"R", "G", "B"};
  std::string s = strf("relMSE       %.6g\nmean ratio   %.6g\n", relMse, meanRatio);
  s += strf("Z-test       %s at alpha %g (Sidak over %zu channel tests: per-test %.3g)\n",
            pass ? "pass" : "FAIL", alpha, tests, perTestLevel);
  s += strf("failing      %zu of %zu pixels (%.4f%%)\n", failingPixels,
            size_t(width) * size_t(height), 100.0 * failingFraction);
  if (worstChannel >= 0) {
    s += strf("worst pixel  (%d, %d) channel %s: z = %.3g\n", worstX, worstY,
              kChannel[worstChannel], worstZ);
  }
  return s;
}

Image zScoreImage(const ZTestResult& result) {
  Image image(result.width, result.height);
  image.rgb = result.z;
  image.meta["content"] = "z-scores";
  return image;
}

namespace {
std::string writeText(const std::string& path, const std::string& text) {
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  std::ofstream out(path);
  out << text;
  if (!out) throw InputError(strf("%s: cannot write", path.c_str()));
  return path;
}
}  // namespace

std::string writeChi2Report(const std::string& dir, const std::string& name, const Chi2Result& r) {
  return writeText((std::filesystem::path(dir) / (name + ".txt")).string(), r.table);
}

std::string writeFailureReport(const std::string& dir, const std::string& name,
                               const ZTestResult& result) {
  return writeText((std::filesystem::path(dir) / (name + "_summary.txt")).string(),
                   result.summary());
}

}  // namespace plume
