// Lights for test scenes built in code.
#pragma once

#include "scene/scene.h"

#include <glm/geometric.hpp>

namespace plume::test {

inline Light sunLight(glm::vec3 toLight, glm::vec3 irradiance) {
  Light l;
  l.type = LightType::Sun;
  l.toLight = glm::normalize(toLight);
  l.irradiance = irradiance;
  return l;
}

inline Light skyLight(glm::vec3 radiance) {
  Light l;
  l.type = LightType::Environment;
  l.radiance = radiance;
  return l;
}

}  // namespace plume::test
