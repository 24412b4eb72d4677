// Image-against-reference checks of the tier-d tests (DESIGN §7), in one place: the per-pixel
// Z-test of core/stats.h (Šidák over every channel test) and an aggregate z-test on the image
// mean. The per-pixel test cannot see a small bias spread over the whole image (each pixel's
// share of it drowns in that pixel's noise); the aggregate test can, and its tolerance shrinks
// with the sample count instead of being a fixed percentage.
#pragma once

#include "core/stats.h"
#include "io/image.h"

#include <glm/common.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <cmath>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace plume::test {

// Family-wise false-positive rate of the aggregate test over its three channel tests. With the
// Šidák correction each channel is tested at 1 - (1 - 1e-3)^(1/3) = 3.3e-4 two-sided: |z| < 3.59.
constexpr double kAggregateAlpha = 1e-3;

struct ReferenceCheckOptions {
  double pixelAlpha = kZTestAlpha;          // family-wise level of the per-pixel Z-test
  double aggregateAlpha = kAggregateAlpha;  // family-wise level of the aggregate test
  // Variance of the image's per-channel mean over all pixels. Unset: the pixels are independent
  // and it is Σ var / N² from the variance channels. Estimators that share samples between
  // pixels (ReSTIR's spatial reuse) correlate them, and that sum then underestimates it: pass the
  // variance measured across independent runs instead.
  std::optional<glm::dvec3> imageMeanVariance;
  // Pixels left out of the per-pixel test (row-major; empty: none), those where the reference
  // rests on too few non-zero samples for a variance (support/resolution.h). The aggregate test
  // keeps every pixel.
  std::vector<bool> unresolved;
  std::string outputGroup = "reference_check";  // failures go to build/test-output/<group>/<test>/
};

// z per channel of mean(image) - mean(reference) over the pixels, divided by its standard error
// (both images' variance channels; the reference's is 0 for exact values).
struct AggregateZResult {
  bool pass = true;
  glm::dvec3 imageMean{0.0}, referenceMean{0.0};
  glm::dvec3 standardError{0.0};
  glm::dvec3 z{0.0};           // ±inf where the means differ and the standard error is 0
  double threshold = 0.0;      // |z| bound of each channel
  double alpha = kAggregateAlpha;
  glm::dvec3 meanRatio() const { return imageMean / referenceMean; }
  // The relative bias that reaches the threshold on average: threshold x standard error / mean.
  // Larger than a few percent, the sample counts are too small for the test to mean much.
  glm::dvec3 resolvableBias() const { return threshold * standardError / glm::abs(referenceMean); }
  std::string summary() const;
};

struct ReferenceCheck {
  ZTestResult pixels;  // over the resolved pixels (its z image has every pixel's)
  AggregateZResult aggregate;
  size_t unresolvedPixels = 0;  // left out of the per-pixel test
  bool pass() const { return pixels.pass && aggregate.pass; }
  std::string summary() const;  // relMSE, mean ratios, both tests' verdicts
};

AggregateZResult aggregateZTest(const Image& image, const Image& reference, const ReferenceCheckOptions& options = {});
AggregateZResult aggregateZTest(const Image& image, std::span<const float> exactRgb,
                                const ReferenceCheckOptions& options = {});

// Both tests, no expectations (for sensitivity checks that must fail).
ReferenceCheck checkAgainstReference(const Image& image, const Image& reference, const ReferenceCheckOptions& options = {});
ReferenceCheck checkAgainstExact(const Image& image, std::span<const float> exactRgb,
                                 const ReferenceCheckOptions& options = {});

// Both tests as gtest expectations; on failure the message names `label` and gives the summary,
// and the images, z-scores and summary go to build/test-output/<outputGroup>/<test>/<label>_*.
ReferenceCheck expectMatchesReference(const Image& image, const Image& reference, const std::string& label,
                                      const ReferenceCheckOptions& options = {});
ReferenceCheck expectMatchesExact(const Image& image, std::span<const float> exactRgb, const std::string& label,
                                  const ReferenceCheckOptions& options = {});

// Two images that must agree to rounding (two pipelines of one estimator): the largest relative
// difference over the channels where `b` is positive, and how many those are.
struct RelativeAgreement {
  double worst = 0.0;
  size_t lit = 0;
};
inline RelativeAgreement relativeAgreement(const Image& a, const Image& b) {
  RelativeAgreement r;
  for (size_t i = 0; i < a.rgb.size() && i < b.rgb.size(); ++i) {
    if (!(b.rgb[i] > 0.0f)) continue;
    ++r.lit;
    r.worst = std::max(r.worst, std::abs(double(a.rgb[i]) - double(b.rgb[i])) / double(b.rgb[i]));
  }
  return r;
}

}  // namespace plume::test
