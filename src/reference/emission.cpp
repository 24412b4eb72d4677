#include "reference/emission.h"

#include "core/blackbody.h"
#include "core/error.h"

#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/Statistics.h>

#include <algorithm>
#include <cmath>

namespace plume::ref {
namespace {
constexpr double kTableMaxKelvin = 20000.0;  // beyond, the exact integral per lookup
}

ReferenceEmission::ReferenceEmission(openvdb::FloatGrid::ConstPtr grid, const Emission& emission)
    : grid_(std::move(grid)), emission_(emission) {
  if (!grid_->transform().isLinear()) throw InputError("grid " + grid_->getName() + ": non-linear transform");
  worldToIndex_ = grid_->transform().baseMap()->getAffineMap()->getMat4().inverse();
  if (!emission_.blackbody) return;
  float hi = grid_->background();
  if (grid_->activeVoxelCount() > 0) hi = std::max(hi, openvdb::tools::minMax(grid_->tree()).max());
  const double tMax = std::min(kTableMaxKelvin, double(emission_.temperatureScale) *
                                                    (std::max(double(hi), 0.0) - emission_.temperatureOffset));
  const int n = tMax > kBlackbodyMinKelvin ? int(std::ceil(tMax - kBlackbodyMinKelvin)) + 2 : 0;
  table_.resize(size_t(n));
  for (int i = 0; i < n; ++i) table_[size_t(i)] = blackbodyRgb(kBlackbodyMinKelvin + i);
}

glm::dvec3 ReferenceEmission::blackbody(double kelvin) const {
  if (!(kelvin > kBlackbodyMinKelvin)) return glm::dvec3(0.0);
  const double x = kelvin - kBlackbodyMinKelvin;
  if (x + 1.0 >= double(table_.size())) return blackbodyRgb(kelvin);
  const size_t i = size_t(x);
  const double f = x - double(i);
  return table_[i] * (1.0 - f) + table_[i + 1] * f;
}

glm::dvec3 ReferenceEmission::radiance(const Accessor& acc, const glm::dvec3& world) const {
  const openvdb::Vec3d p = worldToIndex_.transform(openvdb::Vec3d(world.x, world.y, world.z));
  const double e = openvdb::tools::BoxSampler::sample(acc, p);
  if (emission_.blackbody) {
    return double(emission_.scale) * blackbody(double(emission_.temperatureScale) * (e - emission_.temperatureOffset));
  }
  return double(emission_.scale) * glm::dvec3(emission_.color) * e;
}

}  // namespace plume::ref
