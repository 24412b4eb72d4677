// The CPU reference's own emission (DESIGN §2 "Emission"): the emission grid read with OpenVDB's
// BoxSampler in the grid's own index space (its own transform, so it may differ from the
// density's), and the blackbody colour from core/blackbody.h's spectral integral through the
// reference's own table (1 K steps up to the hottest temperature the grid reaches, exact beyond
// 20000 K) — never the GPU's bake or its log-spaced table, so that a bug in either cannot hide in
// both.
#pragma once

#include "scene/scene.h"

#include <glm/vec3.hpp>
#include <openvdb/openvdb.h>

#include <vector>

namespace plume::ref {

class ReferenceEmission {
 public:
  ReferenceEmission(openvdb::FloatGrid::ConstPtr grid, const Emission& emission);

  using Accessor = openvdb::FloatGrid::ConstAccessor;  // one per thread
  Accessor accessor() const { return grid_->getConstAccessor(); }

  // Le at a world point (radiance; the medium emits sigma_a Le per unit length).
  glm::dvec3 radiance(const Accessor& acc, const glm::dvec3& world) const;
  // The normalised blackbody at T kelvin as this class evaluates it (tests compare it).
  glm::dvec3 blackbody(double kelvin) const;

 private:
  openvdb::FloatGrid::ConstPtr grid_;
  Emission emission_;
  openvdb::math::Mat4d worldToIndex_;
  std::vector<glm::dvec3> table_;  // blackbody at 100 K + i kelvin
};

}  // namespace plume::ref
