// The scene's surfaces on the device (DESIGN §4.3; shaders/surface/surfaces.glsl): the triangles
// loaded and transformed (geometry/scene_mesh.h), Embree's BVH flattened (geometry/bvh.h), each
// input triangle's vertices, shading normals, surface and light density, the surfaces' materials,
// and an alias table over the emissive triangles (chosen in proportion to power: area times the
// mean of Le's channels, as the CPU reference). Built only for scenes with surfaces.
#pragma once

#include "geometry/bvh.h"
#include "gpu/pipeline.h"
#include "scene/scene.h"
#include "shaders/shared/surface_types.h"

#include <cstdint>
#include <vector>

namespace plume {

// Walker's alias table (Vose's construction, in double) over weights w_i > 0, entry i naming
// triangles[i]: surface/surfaces.glsl picks entry i with probability 1/n and keeps it with
// probability keep, else takes entry alias, so triangle i is chosen with probability w_i / sum w.
std::vector<shared::GpuEmitterAlias> emitterAliasTable(const std::vector<double>& weights,
                                                       const std::vector<uint32_t>& triangles);

class GpuSurfaces {
 public:
  // Throws InputError for bad surfaces (an OBJ's file and line, a scene key) and for a mesh
  // larger than the device's storage buffers allow (the message names the buffer).
  GpuSurfaces(gpu::Context& ctx, const Scene& scene);

  // Binds BIND_BVH_NODES .. BIND_EMITTERS, each shifted by `shift` (surface/surfaces.glsl
  // PLUME_SURF_BINDING_SHIFT).
  void bind(gpu::DescriptorSet& set, uint32_t shift = 0) const;
  // A rough estimate of the emitters' radiance scattered at p, phase-averaged:
  // sum of mean(Le) A max(cos, 0) / (4 pi r^2) over the emissive triangles (ReSTIR's light choice).
  double emitterPowerAt(glm::vec3 p) const;
  uint32_t emitterCount() const { return emitterCount_; }
  const geo::BvhStats& bvhStats() const { return stats_; }
  double uploadMs() const { return uploadMs_; }

 private:
  gpu::Buffer nodes_, bvhTriangles_, triangles_, materials_, emitters_;
  uint32_t emitterCount_ = 0;
  struct EmitterSummary {
    glm::vec3 centroid, normal;
    double power;  // area times mean(Le)
  };
  std::vector<EmitterSummary> emitterSummary_;
  geo::BvhStats stats_;
  double uploadMs_ = 0.0;
};

}  // namespace plume
