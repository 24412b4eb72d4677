// The flattened BVH of the scene's triangles, the layout shared by the host (geometry/bvh.h builds
// it from Embree's builder) and the shaders (surface/bvh.glsl traverses it). A binary tree whose
// inner nodes hold the boxes of both children (Aila & Laine 2009, "Understanding the Efficiency of
// Ray Traversal on GPUs"): a traversal step tests both children's boxes from one 64-byte read and
// visits the nearer first. Node 0 is the root; leaves are not nodes but runs of triangles in the
// triangle array, named by the child reference. Triangles store their three world-space vertices
// (the watertight test needs them) and the index of the triangle in the builder's input, which
// names its surface and attributes; with spatial splits one input triangle may be referenced by
// several leaves, so the triangle array may be longer than the input.
// Every vec3 is followed by a 4-byte scalar: std430 and C++ (GLM) agree without hidden padding.
#ifndef PLUME_SHARED_BVH_H
#define PLUME_SHARED_BVH_H

#include "common.h"

PLUME_NS_BEGIN

const uint BVH_NONE = 0xffffffffu;  // a child reference to nothing (the root of 0 or 1 leaf)
const int BVH_MAX_DEPTH = 48;       // nodes on the longest root-to-leaf path, checked by the host
const int BVH_STACK_SIZE = 48;      // traversal stack entries: at most one per level below the root
const uint BVH_MAX_LEAF_SIZE = 4u;  // triangles per leaf

// On the device the whole tree is one texel buffer of uvec4 (BIND_BVH; geo::bvhDeviceTexels):
// texel 0 a header (x: the texel of triangle 0), then the nodes (BVH_NODE_TEXEL_COUNT each, node i
// at 1 + 4 i), then the triangles (BVH_TRIANGLE_TEXEL_COUNT each), then one zero texel. Either kind
// of item is then the same four reads (a triangle's fourth is the next one's first, or the zero
// texel), so the traversal makes one set of reads per loop iteration where a SIMD back end paid
// for a node's and a triangle's in every iteration (surface/bvh.glsl).
const uint BVH_HEADER_TEXELS = 1u;
const uint BVH_NODE_TEXEL_COUNT = 4u;
const uint BVH_TRIANGLE_TEXEL_COUNT = 3u;

// Child c of an inner node: count == 0: inner node `ref` (or nothing when ref == BVH_NONE);
// count > 0: a leaf of `count` triangles starting at triangle `ref`.
struct BvhNode {
  vec3 lo0;
  uint ref0;
  vec3 hi0;
  uint count0;
  vec3 lo1;
  uint ref1;
  vec3 hi1;
  uint count1;
};

struct BvhTriangle {
  vec3 v0;
  uint prim;  // index of the triangle in the builder's input
  vec3 v1;
  uint pad0;
  vec3 v2;
  uint pad1;
};

// A closest hit: t along the ray (world units when the direction is unit length), the input
// triangle's index and Embree's barycentrics (hit = (1 - u - v) v0 + u v1 + v v2).
struct BvhHit {
  float t;
  uint prim;
  float u;
  float v;
};

PLUME_NS_END

#ifdef __cplusplus
#include <cstddef>
static_assert(sizeof(plume::shared::BvhNode) == 64);
static_assert(offsetof(plume::shared::BvhNode, ref0) == 12);
static_assert(offsetof(plume::shared::BvhNode, hi0) == 16);
static_assert(offsetof(plume::shared::BvhNode, count0) == 28);
static_assert(offsetof(plume::shared::BvhNode, lo1) == 32);
static_assert(offsetof(plume::shared::BvhNode, ref1) == 44);
static_assert(offsetof(plume::shared::BvhNode, hi1) == 48);
static_assert(offsetof(plume::shared::BvhNode, count1) == 60);
static_assert(sizeof(plume::shared::BvhTriangle) == 48);
static_assert(offsetof(plume::shared::BvhTriangle, prim) == 12);
static_assert(offsetof(plume::shared::BvhTriangle, v1) == 16);
static_assert(offsetof(plume::shared::BvhTriangle, v2) == 32);
static_assert(sizeof(plume::shared::BvhHit) == 16);
#endif

#endif
