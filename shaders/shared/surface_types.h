// The scene's surfaces on the device beyond the BVH (shared/bvh.h): per input triangle its
// vertices, shading normals, surface and place in the light tree (shared/light_tree.h); per
// surface its material (render/gpu_surfaces.cpp fills them; surface/surfaces.glsl reads them).
// Every vec3 is followed by a 4-byte scalar (std430 and GLM agree).
#ifndef PLUME_SHARED_SURFACE_TYPES_H
#define PLUME_SHARED_SURFACE_TYPES_H

#include "bsdf.h"

PLUME_NS_BEGIN

// A triangle by its input index (BvhTriangle.prim, BvhHit.prim): counter-clockwise seen from its
// front (DESIGN §2 "Surfaces"); n0..n2 are the shading normals where the mesh has them.
struct GpuSurfaceTriangle {
  vec3 v0;
  uint surface;     // index into the materials (scene.surfaces)
  vec3 v1;
  float emitterInvArea;  // an emissive triangle's 1 / area (its points are sampled uniformly; 0: dark)
  vec3 v2;
  uint hasNormals;  // 1: n0..n2 are given
  vec3 n0;
  uint lightTrail;  // an emissive triangle's path from the light tree's root (shared/light_tree.h lt_pmf; 0: dark)
  vec3 n1;
  uint pad1;
  vec3 n2;
  uint pad2;
};

struct GpuSurfaceMaterial {
  Bsdf bsdf;
  vec3 emission;  // radiance leaving the front side
  uint pad0;
};

PLUME_NS_END

#ifdef __cplusplus
#include <cstddef>
static_assert(sizeof(plume::shared::Bsdf) == 32, "Bsdf layout");
static_assert(sizeof(plume::shared::GpuSurfaceTriangle) == 96, "GpuSurfaceTriangle layout");
static_assert(offsetof(plume::shared::GpuSurfaceTriangle, emitterInvArea) == 28, "GpuSurfaceTriangle layout");
static_assert(offsetof(plume::shared::GpuSurfaceTriangle, lightTrail) == 60, "GpuSurfaceTriangle layout");
static_assert(offsetof(plume::shared::GpuSurfaceTriangle, n0) == 48, "GpuSurfaceTriangle layout");
static_assert(sizeof(plume::shared::GpuSurfaceMaterial) == 48, "GpuSurfaceMaterial layout");
static_assert(offsetof(plume::shared::GpuSurfaceMaterial, emission) == 32, "GpuSurfaceMaterial layout");
#endif

#endif
