#include "core/blackbody.h"

#include "shaders/shared/blackbody.h"

#include <algorithm>
#include <cmath>

namespace plume {
namespace {

#include "cie1931_cmf.inc"

constexpr double kH = 6.62607015e-34;   // Planck, J·s
constexpr double kC = 299792458.0;      // m/s
constexpr double kKb = 1.380649e-23;    // Boltzmann, J/K

// The colour-matching functions at lambda nm, linear between the 5 nm samples, 0 outside.
glm::dvec3 cmf(double nm) {
  const double step = (kCmfEndNm - kCmfStartNm) / (kCmfBands - 1);
  const double x = (nm - kCmfStartNm) / step;
  if (x < 0.0 || x > kCmfBands - 1) return glm::dvec3(0.0);
  const int i = std::min(int(x), kCmfBands - 2);
  const double f = x - i;
  return glm::dvec3(kCmfX[i] * (1 - f) + kCmfX[i + 1] * f, kCmfY[i] * (1 - f) + kCmfY[i + 1] * f,
                    kCmfZ[i] * (1 - f) + kCmfZ[i + 1] * f);
}

// ∫ s(λ) cmf(λ) dλ in 1 nm steps (trapezoid) over the table's range.
template <typename Spectrum>
glm::dvec3 integrate(Spectrum&& s) {
  glm::dvec3 sum(0.0);
  const int n = int(std::lround(kCmfEndNm - kCmfStartNm));
  for (int k = 0; k <= n; ++k) {
    const double nm = kCmfStartNm + k;
    const double w = (k == 0 || k == n) ? 0.5 : 1.0;
    sum += w * s(nm) * cmf(nm);
  }
  return sum;
}

}  // namespace

double planck(double lambda, double kelvin) {
  const double l5 = lambda * lambda * lambda * lambda * lambda;
  return 2.0 * kH * kC * kC / (l5 * std::expm1(kH * kC / (lambda * kKb * kelvin)));
}

double cieYIntegral() {
  static const double y = integrate([](double) { return 1.0; }).y;
  return y;
}

glm::dvec3 blackbodyXyz(double kelvin) {
  if (!(kelvin > kBlackbodyMinKelvin)) return glm::dvec3(0.0);
  const double peak = planck(kWienDisplacement / kelvin, kelvin);
  return integrate([&](double nm) { return planck(nm * 1e-9, kelvin) / peak; }) / cieYIntegral();
}

glm::dvec3 xyzToRec709(const glm::dvec3& c) {
  return {3.2404542 * c.x - 1.5371385 * c.y - 0.4985314 * c.z,
          -0.9692660 * c.x + 1.8760108 * c.y + 0.0415560 * c.z,
          0.0556434 * c.x - 0.2040259 * c.y + 1.0572252 * c.z};
}

glm::dvec3 blackbodyRgb(double kelvin) { return glm::max(xyzToRec709(blackbodyXyz(kelvin)), glm::dvec3(0.0)); }

std::vector<glm::vec4> blackbodyTable() {
  std::vector<glm::vec4> t(shared::BB_TABLE_SIZE);
  for (uint32_t i = 0; i < shared::BB_TABLE_SIZE; ++i) {
    // The entry's temperature in double (the float bb_table_kelvin rounds by ~1e-7).
    const double k = double(shared::BB_TABLE_MIN_K) *
                     std::exp(double(shared::BB_TABLE_LOG_RANGE) * i / double(shared::BB_TABLE_SIZE - 1));
    t[i] = glm::vec4(glm::vec3(blackbodyRgb(k)), 0.0f);
  }
  return t;
}

}  // namespace plume
