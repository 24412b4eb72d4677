#include "support/reference_check.h"

#include "core/log.h"
#include "io/failure_images.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <stdexcept>

namespace plume::test {

namespace {

// |z| with two-sided p-value `level` (bisection on twoSidedPValue, which decreases in |z|).
double twoSidedThreshold(double level) {
  double lo = 0.0, hi = 40.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (twoSidedPValue(mid) > level ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// refVar empty: exact reference values.
AggregateZResult aggregateArrays(std::span<const float> a, std::span<const float> aVar, std::span<const float> b,
                                 std::span<const float> bVar, const ReferenceCheckOptions& options) {
  if (a.size() != b.size() || a.size() != aVar.size() || (!bVar.empty() && bVar.size() != b.size()) ||
      a.size() % 3 != 0 || a.empty()) {
    throw std::invalid_argument("aggregateZTest: images of different sizes, empty, or without variance");
  }
  AggregateZResult r;
  r.alpha = options.aggregateAlpha;
  r.threshold = twoSidedThreshold(sidakLevel(options.aggregateAlpha, 3));
  const double n = double(a.size() / 3);
  glm::dvec3 sumA(0.0), sumB(0.0), varA(0.0), varB(0.0);
  for (size_t i = 0; i < a.size(); ++i) {
    const int c = int(i % 3);
    sumA[c] += a[i];
    sumB[c] += b[i];
    varA[c] += aVar[i];
    if (!bVar.empty()) varB[c] += bVar[i];
  }
  r.imageMean = sumA / n;
  r.referenceMean = sumB / n;
  // Var(mean) = Σ var_p / N² for independent pixels.
  const glm::dvec3 meanVarA = options.imageMeanVariance ? *options.imageMeanVariance : varA / (n * n);
  const glm::dvec3 meanVarB = varB / (n * n);
  for (int c = 0; c < 3; ++c) {
    const double diff = r.imageMean[c] - r.referenceMean[c], var = meanVarA[c] + meanVarB[c];
    r.standardError[c] = std::sqrt(std::max(var, 0.0));
    if (!std::isfinite(diff) || !std::isfinite(var)) {
      r.z[c] = std::numeric_limits<double>::infinity();
    } else if (r.standardError[c] > 0.0) {
      r.z[c] = diff / r.standardError[c];
    } else {
      r.z[c] = diff == 0.0 ? 0.0 : std::copysign(std::numeric_limits<double>::infinity(), diff);
    }
    r.pass &= std::abs(r.z[c]) < r.threshold;
  }
  return r;
}

// The per-pixel test of `full` (every pixel's) redone over the pixels not in `unresolved`: the
// Šidák level, the verdict, the failing count and the worst pixel are those of the resolved
// pixels; relMSE, the mean ratio and the z image stay those of the whole image.
ZTestResult resolvedOnly(ZTestResult full, const std::vector<bool>& unresolved) {
  if (unresolved.empty()) return full;
  if (unresolved.size() * 3 != full.z.size()) throw std::invalid_argument("unresolved: one entry per pixel expected");
  const size_t tested = size_t(std::count(unresolved.begin(), unresolved.end(), false));
  full.tests = 3 * tested;
  full.perTestLevel = sidakLevel(full.alpha, double(std::max<size_t>(full.tests, 1)));
  full.failingPixels = 0;
  full.worstZ = 0.0;
  full.worstX = full.worstY = full.worstChannel = -1;
  double worst = -1.0;
  for (size_t p = 0; p < unresolved.size(); ++p) {
    if (unresolved[p]) continue;
    bool fails = false;
    for (int c = 0; c < 3; ++c) {
      const double z = full.z[3 * p + size_t(c)];  // core/stats.cpp's channelZ: never NaN
      fails |= twoSidedPValue(z) < full.perTestLevel;
      if (std::abs(z) > worst) {
        worst = std::abs(z);
        full.worstZ = z;
        full.worstX = int(p % size_t(full.width));
        full.worstY = int(p / size_t(full.width));
        full.worstChannel = c;
      }
    }
    full.failingPixels += fails ? 1 : 0;
  }
  full.pass = full.failingPixels == 0;
  full.failingFraction = tested ? double(full.failingPixels) / double(tested) : 0.0;
  return full;
}

void requireVariance(const Image& image, const char* which) {
  if (!image.hasVariance()) throw std::invalid_argument(strf("aggregateZTest: the %s has no variance channels", which));
}

ReferenceCheck expectCheck(ReferenceCheck check, const Image& image, const Image& reference, const std::string& label,
                           const ReferenceCheckOptions& options) {
  // One line per check, pass or fail: the bias the aggregate test resolves shows whether the
  // sample counts still suffice.
  const AggregateZResult& agg = check.aggregate;
  const glm::dvec3 ratio = agg.meanRatio(), z = agg.z, resolved = agg.resolvableBias();
  std::printf("[check] %s: relMSE %.3g, mean ratio %.4f %.4f %.4f, aggregate z %.2f %.2f %.2f (resolves a bias of "
              "%.2g%%), worst pixel z %.2f%s\n",
              label.c_str(), check.pixels.relMse, ratio.x, ratio.y, ratio.z, z.x, z.y, z.z,
              100.0 * std::max({resolved.x, resolved.y, resolved.z}), check.pixels.worstZ,
              check.unresolvedPixels ? strf(" (%zu unresolved pixels left out)", check.unresolvedPixels).c_str() : "");
  EXPECT_TRUE(check.pass()) << label << ":\n" << check.summary();
  if (!check.pass()) {
    const std::string dir = outputDir(options.outputGroup);
    writeFailureImages(dir, label, image, reference, check.pixels);
    std::ofstream(dir + "/" + label + "_summary.txt") << check.summary();  // both tests, not only the per-pixel one
  }
  return check;
}

}  // namespace

std::string AggregateZResult::summary() const {
  const glm::dvec3 ratio = meanRatio(), bias = resolvableBias();
  return strf("aggregate    %s at alpha %g (Sidak over 3 channels: |z| < %.2f)\n"
              "  mean ratio %.5f %.5f %.5f (R G B)\n"
              "  z          %.2f %.2f %.2f\n"
              "  resolves   a bias of %.2g%% %.2g%% %.2g%% (threshold x standard error / reference mean)\n",
              pass ? "pass" : "FAIL", alpha, threshold, ratio.x, ratio.y, ratio.z, z.x, z.y, z.z, 100.0 * bias.x,
              100.0 * bias.y, 100.0 * bias.z);
}

std::string ReferenceCheck::summary() const {
  const std::string left =
      unresolvedPixels ? strf("unresolved   %zu pixels left out of the per-pixel test (support/resolution.h)\n", unresolvedPixels)
                       : std::string();
  return pixels.summary() + left + aggregate.summary();
}

AggregateZResult aggregateZTest(const Image& image, const Image& reference, const ReferenceCheckOptions& options) {
  requireVariance(image, "image");
  requireVariance(reference, "reference");
  return aggregateArrays(image.rgb, image.var, reference.rgb, reference.var, options);
}

AggregateZResult aggregateZTest(const Image& image, std::span<const float> exactRgb, const ReferenceCheckOptions& options) {
  requireVariance(image, "image");
  return aggregateArrays(image.rgb, image.var, exactRgb, {}, options);
}

ReferenceCheck checkAgainstReference(const Image& image, const Image& reference, const ReferenceCheckOptions& options) {
  return {resolvedOnly(zTest(image, reference, options.pixelAlpha), options.unresolved),
          aggregateZTest(image, reference, options), size_t(std::count(options.unresolved.begin(), options.unresolved.end(), true))};
}

ReferenceCheck checkAgainstExact(const Image& image, std::span<const float> exactRgb,
                                 const ReferenceCheckOptions& options) {
  return {resolvedOnly(zTestAgainst(image, exactRgb, options.pixelAlpha), options.unresolved),
          aggregateZTest(image, exactRgb, options), size_t(std::count(options.unresolved.begin(), options.unresolved.end(), true))};
}

ReferenceCheck expectMatchesReference(const Image& image, const Image& reference, const std::string& label,
                                      const ReferenceCheckOptions& options) {
  return expectCheck(checkAgainstReference(image, reference, options), image, reference, label, options);
}

ReferenceCheck expectMatchesExact(const Image& image, std::span<const float> exactRgb, const std::string& label,
                                  const ReferenceCheckOptions& options) {
  Image exact = image;
  exact.rgb.assign(exactRgb.begin(), exactRgb.end());
  exact.var.assign(exact.rgb.size(), 0.0f);
  return expectCheck(checkAgainstExact(image, exactRgb, options), image, exact, label, options);
}

}  // namespace plume::test
