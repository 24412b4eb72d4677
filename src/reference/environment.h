// The CPU reference's environment map (DESIGN §2), written independently of the shaders'
// (shared/envmap.h): its own orientation (quaternions), texel lookup, and importance sampling
// from one flat CDF over all texels weighted by mean radiance times the texel's exact solid
// angle, with a uniform direction in solid angle inside the texel. Reads the EXR through the
// io layer (loadEnvironmentMap), as the GPU estimators do.
#pragma once

#include "io/environment_map.h"
#include "scene/scene.h"

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include <string>
#include <vector>

namespace plume::ref {

class ReferenceEnvironmentMap {
 public:
  // `key` names the light's map in errors, e.g. "scene.json: lights[0].map".
  ReferenceEnvironmentMap(const Light& light, const std::string& key);

  // Radiance (times the light's scale) arriving from unit world direction w.
  glm::dvec3 radiance(const glm::dvec3& w) const;
  // A unit world direction drawn from the map's distribution (u in [0, 1)^3: two for the texel,
  // two inside it) and its pdf per solid angle.
  glm::dvec3 sample(double uTexel, double uPhi, double uCos, double& pdf) const;
  double pdf(const glm::dvec3& w) const;

 private:
  size_t texelOf(const glm::dvec3& w) const;  // index row * W + column
  double texelSolidAngle(int row) const;

  int width_ = 0, height_ = 0;
  std::vector<glm::dvec3> texels_;
  std::vector<double> cdf_;    // cdf_[i + 1] = P(texel <= i); empty: black map (uniform sphere)
  glm::dquat toLocal_{1, 0, 0, 0};
};

}  // namespace plume::ref
