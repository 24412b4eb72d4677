#include "viewer/orbit_camera.h"

#include <glm/glm.hpp>
#include <glm/gtc/constants.hpp>

#include <cmath>

namespace plume::viewer {
namespace {

constexpr float kMaxPitch = glm::radians(89.0f);

// An orthonormal frame with `up` as the y axis (any x, z): yaw and pitch are measured in it.
void upFrame(glm::vec3 up, glm::vec3& x, glm::vec3& y, glm::vec3& z) {
  y = glm::normalize(up);
  const glm::vec3 helper = std::abs(y.z) < 0.9f ? glm::vec3(0, 0, 1) : glm::vec3(1, 0, 0);
  x = glm::normalize(glm::cross(y, helper));
  z = glm::cross(x, y);
}

}  // namespace

void OrbitCamera::reset(const CameraPose& pose) {
  base_ = pose;
  target_ = pose.lookAt;
  const glm::vec3 offset = pose.position - pose.lookAt;
  distance_ = std::max(1e-4f, glm::length(offset));
  glm::vec3 x, y, z;
  upFrame(pose.up, x, y, z);
  const glm::vec3 d = offset / distance_;
  pitch_ = std::asin(glm::clamp(glm::dot(d, y), -1.0f, 1.0f));
  pitch_ = glm::clamp(pitch_, -kMaxPitch, kMaxPitch);
  yaw_ = std::atan2(glm::dot(d, x), glm::dot(d, z));
}

void OrbitCamera::orbit(glm::vec2 delta, float viewHeight) {
  const float perPixel = glm::pi<float>() / std::max(1.0f, viewHeight);
  yaw_ -= delta.x * perPixel;
  pitch_ = glm::clamp(pitch_ + delta.y * perPixel, -kMaxPitch, kMaxPitch);
}

void OrbitCamera::pan(glm::vec2 delta, float viewHeight) {
  const CameraPose p = pose();
  const glm::vec3 forward = glm::normalize(p.lookAt - p.position);
  const glm::vec3 right = glm::normalize(glm::cross(forward, p.up));
  const glm::vec3 up = glm::cross(right, forward);
  // World units per pixel at the target's depth.
  const float perPixel = 2.0f * distance_ * std::tan(glm::radians(p.fovY) * 0.5f) / std::max(1.0f, viewHeight);
  target_ += (-delta.x * right + delta.y * up) * perPixel;
}

void OrbitCamera::zoom(float steps) { distance_ = std::max(1e-4f, distance_ * std::pow(0.9f, steps)); }

CameraPose OrbitCamera::pose() const {
  glm::vec3 x, y, z;
  upFrame(base_.up, x, y, z);
  const glm::vec3 d = std::cos(pitch_) * (std::sin(yaw_) * x + std::cos(yaw_) * z) + std::sin(pitch_) * y;
  CameraPose p = base_;
  p.lookAt = target_;
  p.position = target_ + distance_ * d;
  return p;
}

}  // namespace plume::viewer
