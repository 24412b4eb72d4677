// Orbit / pan / zoom around a target point, kept as the scene's look-at camera pose (DESIGN §2
// Camera): the viewer edits a CameraPose, so the renderers see an ordinary pose.
#pragma once

#include "scene/scene.h"

#include <glm/vec2.hpp>

namespace plume::viewer {

class OrbitCamera {
 public:
  OrbitCamera() = default;
  explicit OrbitCamera(const CameraPose& pose) { reset(pose); }
  void reset(const CameraPose& pose);

  // Mouse deltas in pixels of a window `viewHeight` pixels tall.
  void orbit(glm::vec2 deltaPixels, float viewHeight);  // drag: 180 degrees per window height
  void pan(glm::vec2 deltaPixels, float viewHeight);    // the target moves with the cursor
  void zoom(float wheelSteps);                          // distance *= 0.9^steps

  CameraPose pose() const;
  float distance() const { return distance_; }

 private:
  CameraPose base_;    // fov and up come from here
  glm::vec3 target_{0.0f};
  float distance_ = 1.0f;
  float yaw_ = 0.0f;   // around `up`, radians
  float pitch_ = 0.0f; // elevation, radians, within +-89 degrees
};

}  // namespace plume::viewer
