// The scene's surfaces on the device (DESIGN §4.3; shaders/surface/surfaces.glsl): the triangles
// loaded and transformed (geometry/scene_mesh.h), Embree's BVH flattened (geometry/bvh.h), each
// input triangle's vertices, shading normals, surface and place in the light tree, the surfaces'
// materials, and the light tree over the emissive triangles (a shading point picks them by their
// power, distance and orientation: shaders/shared/light_tree.h). Built only for scenes with surfaces.
#pragma once

#include "geometry/bvh.h"
#include "gpu/pipeline.h"
#include "scene/scene.h"
#include "shaders/shared/light_tree.h"
#include "shaders/shared/surface_types.h"

#include <cstdint>
#include <vector>

namespace plume {

// The light tree over the emissive triangles (shaders/shared/light_tree.h): nodes[0] is the root,
// the children of an inner node are adjacent, and trails[i] is emitter i's path from the root
// (lt_pmf's encoding). Built top down, each node split at the plane of least SAOH cost (power x
// orientation measure x box area of the two children, pbrt-v4's BVHLightSampler), or at the median
// centroid along the longest axis where no plane separates the centroids or a child would be too
// large for the trails' bits: its depth is at most 30 (n < 2^30).
struct LightTreeEmitter {
  glm::vec3 v0, v1, v2;
  double power;       // area times mean(Le)
  uint32_t triangle;  // input index
};
struct LightTree {
  std::vector<shared::GpuLightNode> nodes;
  std::vector<uint32_t> trails;
  int depth = 0;
};
LightTree buildLightTree(const std::vector<LightTreeEmitter>& emitters);

class GpuSurfaces {
 public:
  // Throws InputError for bad surfaces (an OBJ's file and line, a scene key) and for a mesh
  // larger than the device's texel buffers allow (the message names the buffer).
  GpuSurfaces(gpu::Context& ctx, const Scene& scene);

  // Binds BIND_BVH .. BIND_EMITTERS, each shifted by `shift` (surface/surfaces.glsl
  // PLUME_SURF_BINDING_SHIFT).
  void bind(gpu::DescriptorSet& set, uint32_t shift = 0) const;
  // Their descriptor types: uniform texel buffers of uvec4 (surface/texels.glsl).
  static gpu::BindingTypes bindingTypes(uint32_t shift = 0);
  // A rough estimate of the emitters' radiance scattered at p, phase-averaged:
  // sum of mean(Le) A max(cos, 0) / (4 pi r^2) over the emissive triangles (ReSTIR's light choice).
  double emitterPowerAt(glm::vec3 p) const;
  uint32_t emitterCount() const { return emitterCount_; }
  // The emissive triangles' corners, three per triangle, as the device holds them (world space).
  const std::vector<glm::vec3>& emitterVertices() const { return emitterVertices_; }
  // Their triangles' indices on the device (the prim of surface/surfaces.glsl), in that order.
  const std::vector<uint32_t>& emitterTriangles() const { return emitterTriangles_; }
  // And their Le's luminance, the mean of its channels (restir/bridge.glsl rs_luminance).
  const std::vector<float>& emitterLuminance() const { return emitterLuminance_; }
  const geo::BvhStats& bvhStats() const { return stats_; }
  double uploadMs() const { return uploadMs_; }

 private:
  gpu::TexelBuffer bvh_, triangles_, materials_, emitters_;
  uint32_t emitterCount_ = 0;
  int lightTreeDepth_ = 0;
  struct EmitterSummary {
    glm::vec3 centroid, normal;
    double power;  // area times mean(Le)
  };
  std::vector<EmitterSummary> emitterSummary_;
  std::vector<glm::vec3> emitterVertices_;
  std::vector<uint32_t> emitterTriangles_;
  std::vector<float> emitterLuminance_;
  geo::BvhStats stats_;
  double uploadMs_ = 0.0;
};

}  // namespace plume
