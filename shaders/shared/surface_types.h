// The scene's surfaces on the device beyond the BVH (shared/bvh.h): per input triangle its
// vertices, shading normals, surface and light density; per surface its material; the emissive
// triangles' alias table (render/gpu_surfaces.cpp fills them; surface/surfaces.glsl reads them).
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
  float lightPdf;   // the area density with which emitter sampling picks its points (0: dark)
  vec3 v2;
  uint hasNormals;  // 1: n0..n2 are given
  vec3 n0;
  uint pad0;
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

// One entry of the alias table over the emissive triangles (Walker; Vose's construction): entry
// i keeps its own triangle with probability `keep`, else hands over to entry `alias`.
struct GpuEmitterAlias {
  float keep;
  uint alias;
  uint triangle;  // the entry's triangle (input index)
  float pad0;
};

PLUME_NS_END

#ifdef __cplusplus
#include <cstddef>
static_assert(sizeof(plume::shared::Bsdf) == 32, "Bsdf layout");
static_assert(sizeof(plume::shared::GpuSurfaceTriangle) == 96, "GpuSurfaceTriangle layout");
static_assert(offsetof(plume::shared::GpuSurfaceTriangle, lightPdf) == 28, "GpuSurfaceTriangle layout");
static_assert(offsetof(plume::shared::GpuSurfaceTriangle, n0) == 48, "GpuSurfaceTriangle layout");
static_assert(sizeof(plume::shared::GpuSurfaceMaterial) == 48, "GpuSurfaceMaterial layout");
static_assert(offsetof(plume::shared::GpuSurfaceMaterial, emission) == 32, "GpuSurfaceMaterial layout");
static_assert(sizeof(plume::shared::GpuEmitterAlias) == 16, "GpuEmitterAlias layout");
#endif

#endif
