// Triangle meshes on the host (DESIGN §2 "Surfaces"): positions and triangles by index, optional
// shading normals by their own index, and the objects (`o`/`g`) the triangles came from. A
// triangle's front side is the one from which its vertices run counter-clockwise; shading
// normals only shade. Built-in shapes (a plane) and the scene's affine transforms live here too.
#pragma once

#include <glm/glm.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace plume::geo {

constexpr uint32_t kNoNormal = 0xffffffffu;

struct TriangleMesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;           // shading normals (OBJ `vn`), unit length
  std::vector<glm::uvec3> triangles;        // indices into positions, counter-clockwise from the front
  std::vector<glm::uvec3> triangleNormals;  // per triangle: indices into normals, or all kNoNormal
  std::vector<uint32_t> triangleObject;     // per triangle: index into objects
  std::vector<std::string> objects;         // names of the `o`/`g` objects ("" before the first)

  size_t triangleCount() const { return triangles.size(); }
  bool hasNormals(size_t tri) const { return triangleNormals[tri].x != kNoNormal; }
  // Appends `other` (indices shifted; its objects appended after this mesh's).
  void append(const TriangleMesh& other);
};

// Twice the triangle's area, in double precision; 0 for a degenerate (collinear) triangle.
double doubleArea(const TriangleMesh& mesh, size_t tri);

// An affine map. The scene's form: x' = T R S x with R = Rz Ry Rx (rotations about the world axes
// in the order X, then Y, then Z: Blender's "XYZ Euler"), angles in degrees, right-handed.
struct Transform {
  glm::mat4 matrix{1.0f};  // column-major (GLM): matrix[3] is the translation
  static Transform fromTrs(glm::vec3 translate, glm::vec3 rotateDeg, glm::vec3 scale);
};

// Applies `t` to positions and, by the inverse transpose, to normals (renormalised). A map that
// mirrors (negative determinant) also reverses every triangle's winding, so that the front side
// stays the side the mesh's author meant. Throws InputError (prefixed by `what`) for a matrix
// that is not affine, holds a NaN/Inf, or is singular.
void applyTransform(TriangleMesh& mesh, const Transform& t, const std::string& what);

// A rectangle of size.x by size.y centred on `centre`, facing `normal` (two triangles,
// counter-clockwise seen from the normal's side). Its axes: u = normalize(cross(normal, a)) with
// a = +Z (+X when the normal is within 1e-3 of ±Z) carries size.x, v = cross(normal, u) carries
// size.y; for the ground (normal +Y): u = +X, v = -Z. Throws InputError (prefixed by `what`) for
// a zero or non-finite normal or a size that is not positive.
TriangleMesh makePlane(glm::vec3 centre, glm::vec3 normal, glm::vec2 size, const std::string& what);

}  // namespace plume::geo
