// The scene's surfaces (scene/scene.h Surface) as one world-space triangle mesh: each OBJ loaded
// (geometry/obj.h) or plane made (mesh.h makePlane), transformed, and appended in the order of
// `surfaces[]`; each triangle remembers its surface (its material and emission). The input the
// BVH build (bvh.h) and the CPU reference's Embree scene both take.
#pragma once

#include "geometry/mesh.h"
#include "scene/scene.h"
#include "shaders/shared/bsdf.h"

#include <vector>

namespace plume::geo {

struct SceneMesh {
  TriangleMesh mesh;                      // world space
  std::vector<uint32_t> triangleSurface;  // per triangle: index into scene.surfaces
  std::vector<size_t> degenerate;         // per surface: zero-area triangles dropped (warned about)
};

// Throws InputError: an OBJ's errors name its file and line, a transform's name
// "<scene>: surfaces[i].transform", a surface left without triangles names "surfaces[i]".
SceneMesh loadSceneSurfaces(const Scene& scene);

// The surface's material as the BSDF of shared/bsdf.h (diffuse albedo, or a conductor's f0 and
// GGX alpha); emission is not a BSDF property.
shared::Bsdf surfaceBsdf(const Surface& s);

}  // namespace plume::geo
