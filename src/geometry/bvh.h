// The scene's triangles as the shaders traverse them (DESIGN §4.3): Embree's builder on the CPU,
// flattened into the node and triangle layout of shaders/shared/bvh.h; and the Embree scene that
// the CPU reference and the tests intersect directly (its own code path, so that a bug in the
// flattening or the shader traversal cannot hide in both).
#pragma once

#include "geometry/mesh.h"
#include "shaders/shared/bvh.h"

#include <memory>
#include <vector>

namespace plume::geo {

struct BvhStats {
  size_t inputTriangles = 0;
  size_t references = 0;  // triangles in the flattened array (> input with spatial splits)
  size_t nodes = 0;
  size_t leaves = 0;
  int depth = 0;          // inner nodes on the longest root-to-leaf path
  double buildMs = 0.0;   // Embree's build
  double flattenMs = 0.0;
  size_t bytes = 0;       // the device's texels: header, nodes, triangles, padding
  double bytesPerTriangle() const { return inputTriangles ? double(bytes) / double(inputTriangles) : 0.0; }
};

struct FlatBvh {
  std::vector<shared::BvhNode> nodes;          // node 0 is the root (always present)
  std::vector<shared::BvhTriangle> triangles;  // leaves' runs; prim = index into the mesh's triangles
  BvhStats stats;
};

struct BvhOptions {
  // Spatial splits (Stich et al. 2009, "Spatial Splits in Bounding Volume Hierarchies"): a
  // triangle may be cut between leaves, which tightens the boxes of long thin triangles (a
  // ground plane) at the price of duplicate references.
  bool spatialSplits = true;
};

// Builds with Embree's rtcBuildBVH (RTC_BUILD_QUALITY_HIGH: binned SAH, with spatial splits when
// enabled), binary, at most BVH_MAX_LEAF_SIZE triangles a leaf. Throws InputError when the tree
// is deeper than the shader's traversal stack or holds 2^29 or more triangle references,
// InternalError or DeviceError when Embree fails.
FlatBvh buildBvh(const TriangleMesh& mesh, const BvhOptions& options = {});

// The tree as the shaders read it: one array of 16-byte texels, the header, the nodes, the
// triangles and a zero texel (shared/bvh.h, "On the device").
std::vector<glm::uvec4> bvhDeviceTexels(const FlatBvh& bvh);

// An Embree scene of one triangle mesh (primID = triangle index), built with
// RTC_BUILD_QUALITY_HIGH and RTC_SCENE_FLAG_ROBUST (watertight intersection).
class EmbreeScene {
 public:
  explicit EmbreeScene(const TriangleMesh& mesh);
  ~EmbreeScene();
  // Embree scenes constructed so far in this process (a scene without surfaces must build none).
  static size_t built();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  // Closest hit with t in [tMin, tMax]; prim == BVH_NONE and t = tMax on a miss.
  shared::BvhHit intersect(glm::vec3 origin, glm::vec3 dir, float tMin, float tMax) const;
  // Whether any triangle is hit with t in [tMin, tMax].
  bool occluded(glm::vec3 origin, glm::vec3 dir, float tMin, float tMax) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace plume::geo
