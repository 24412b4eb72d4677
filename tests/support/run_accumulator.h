// Mean and variance of the mean of independent images (one a run of a reusing estimator), and
// the variance of the image's mean over pixels: spatial reuse shares samples between the pixels
// of one run, so the per-pixel variances do not add up to it; the spread of each run's image
// mean does (ReferenceCheckOptions::imageMeanVariance).
#pragma once

#include "io/image.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <vector>

namespace plume::test {

struct RunAccumulator {
  std::vector<double> sum, sum2;
  glm::dvec3 meanSum{0.0}, meanSum2{0.0};
  int n = 0;
  void add(const Image& im) {
    if (sum.empty()) sum.assign(im.rgb.size(), 0.0), sum2.assign(im.rgb.size(), 0.0);
    glm::dvec3 m(0.0);
    for (size_t i = 0; i < im.rgb.size(); ++i) {
      sum[i] += im.rgb[i], sum2[i] += double(im.rgb[i]) * im.rgb[i];
      m[int(i % 3)] += im.rgb[i];
    }
    m /= double(im.rgb.size() / 3);
    meanSum += m, meanSum2 += m * m;
    ++n;
  }
  Image image(int w, int h) const {
    Image out(w, h, true);
    for (size_t i = 0; i < sum.size(); ++i) {
      const double mean = sum[i] / n;
      out.rgb[i] = float(mean);
      out.var[i] = float(std::max(0.0, (sum2[i] / n - mean * mean)) * n / (n - 1.0) / n);
    }
    return out;
  }
  // Variance of the mean over runs of the image's per-channel mean over pixels.
  glm::dvec3 imageMeanVariance() const {
    const glm::dvec3 mean = meanSum / double(n);
    return glm::max(meanSum2 / double(n) - mean * mean, glm::dvec3(0.0)) * (n / (n - 1.0)) / double(n);
  }
};

}  // namespace plume::test
