#include "reference/environment.h"

#include <glm/glm.hpp>
#define GLM_ENABLE_EXPERIMENTAL
#include <glm/gtx/quaternion.hpp>

#include <algorithm>
#include <cmath>

namespace plume::ref {

using glm::dvec3;

ReferenceEnvironmentMap::ReferenceEnvironmentMap(const Light& light, const std::string& key) {
  const EnvironmentMapImage image = loadEnvironmentMap(light.map, key);
  width_ = image.width;
  height_ = image.height;
  texels_.resize(image.texels.size());
  for (size_t i = 0; i < texels_.size(); ++i) texels_[i] = dvec3(image.texels[i]) * double(light.scale);

  // Orientation: q_up takes `up` to +Y by the shortest arc (a half turn about X for up = -Y),
  // then a turn of -rotate_y_deg about +Y (right-handed).
  const dvec3 up = glm::normalize(dvec3(light.up));
  const dvec3 y(0, 1, 0);
  glm::dquat qUp = glm::dot(up, y) < -1.0 + 1e-12 ? glm::angleAxis(M_PI, dvec3(1, 0, 0)) : glm::rotation(up, y);
  glm::dquat qRot = glm::angleAxis(-glm::radians(double(light.rotateYDeg)), y);
  toLocal_ = qRot * qUp;

  // One CDF over all texels: weight = mean of R, G, B times the texel's solid angle.
  cdf_.assign(texels_.size() + 1, 0.0);
  for (int r = 0; r < height_; ++r) {
    const double omega = texelSolidAngle(r);
    for (int c = 0; c < width_; ++c) {
      const size_t i = size_t(r) * width_ + c;
      const dvec3& L = texels_[i];
      cdf_[i + 1] = cdf_[i] + (L.x + L.y + L.z) / 3.0 * omega;
    }
  }
  const double total = cdf_.back();
  if (total > 0.0) {
    for (double& v : cdf_) v /= total;
  } else {
    cdf_.clear();  // black: sampled uniformly on the sphere
  }
}

double ReferenceEnvironmentMap::texelSolidAngle(int row) const {
  const double theta0 = M_PI * row / height_, theta1 = M_PI * (row + 1) / height_;
  return (std::cos(theta0) - std::cos(theta1)) * 2.0 * M_PI / width_;
}

size_t ReferenceEnvironmentMap::texelOf(const dvec3& w) const {
  const dvec3 d = toLocal_ * w;
  double phi = std::atan2(d.x, -d.z);  // column 0 looks along local -Z
  if (phi < 0) phi += 2.0 * M_PI;
  const double theta = std::acos(std::clamp(d.y, -1.0, 1.0));
  const int c = std::min(width_ - 1, int(phi / (2.0 * M_PI) * width_));
  const int r = std::min(height_ - 1, int(theta / M_PI * height_));
  return size_t(r) * width_ + size_t(c);
}

dvec3 ReferenceEnvironmentMap::radiance(const dvec3& w) const { return texels_[texelOf(w)]; }

double ReferenceEnvironmentMap::pdf(const dvec3& w) const {
  if (cdf_.empty()) return 1.0 / (4.0 * M_PI);
  const size_t i = texelOf(w);
  return (cdf_[i + 1] - cdf_[i]) / texelSolidAngle(int(i / size_t(width_)));
}

dvec3 ReferenceEnvironmentMap::sample(double uTexel, double uPhi, double uCos, double& pdf) const {
  dvec3 local;
  if (cdf_.empty()) {
    const double z = 1.0 - 2.0 * uCos, s = std::sqrt(std::max(0.0, 1.0 - z * z));
    local = dvec3(s * std::cos(2.0 * M_PI * uPhi), z, s * std::sin(2.0 * M_PI * uPhi));
    pdf = 1.0 / (4.0 * M_PI);
  } else {
    // The first texel whose cumulative probability exceeds uTexel (never one of probability 0).
    const size_t i = size_t(std::upper_bound(cdf_.begin() + 1, cdf_.end(), uTexel) - cdf_.begin()) - 1;
    const size_t k = std::min(i, texels_.size() - 1);
    const int r = int(k / size_t(width_)), c = int(k % size_t(width_));
    const double phi = 2.0 * M_PI * (c + uPhi) / width_;
    const double cos0 = std::cos(M_PI * r / height_), cos1 = std::cos(M_PI * (r + 1) / height_);
    const double cosTheta = cos0 + (cos1 - cos0) * uCos;  // uniform in solid angle in the texel
    const double sinTheta = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta));
    local = dvec3(sinTheta * std::sin(phi), cosTheta, -sinTheta * std::cos(phi));
    pdf = (cdf_[k + 1] - cdf_[k]) / texelSolidAngle(r);
  }
  return glm::normalize(glm::inverse(toLocal_) * local);
}

}  // namespace plume::ref
