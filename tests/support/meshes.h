// Closed triangle meshes made in code for the surface tests: every triangle counter-clockwise seen
// from outside, vertices shared between neighbours (so edges and vertices are exact ties).
#pragma once

#include "geometry/mesh.h"

namespace plume::test {

// The cube [-h, h]^3, 12 triangles.
geo::TriangleMesh makeCube(float h = 1.0f);
// A latitude/longitude sphere of `rings` bands and `segments` meridians (single triangles at the
// poles, 2 * segments * (rings - 1) triangles).
geo::TriangleMesh makeSphere(glm::vec3 centre, float radius, int rings, int segments);
// A torus around +Y: major radius R, minor radius r, 2 * nu * nv triangles.
geo::TriangleMesh makeTorus(glm::vec3 centre, float R, float r, int nu, int nv);

}  // namespace plume::test
