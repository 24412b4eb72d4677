#include "geometry/mesh.h"

#include "core/error.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>

namespace plume::geo {

void TriangleMesh::append(const TriangleMesh& other) {
  const uint32_t p0 = uint32_t(positions.size()), n0 = uint32_t(normals.size()), o0 = uint32_t(objects.size());
  positions.insert(positions.end(), other.positions.begin(), other.positions.end());
  normals.insert(normals.end(), other.normals.begin(), other.normals.end());
  objects.insert(objects.end(), other.objects.begin(), other.objects.end());
  for (size_t i = 0; i < other.triangles.size(); ++i) {
    triangles.push_back(other.triangles[i] + glm::uvec3(p0));
    const glm::uvec3 n = other.triangleNormals[i];
    triangleNormals.push_back(n.x == kNoNormal ? n : n + glm::uvec3(n0));
    triangleObject.push_back(other.triangleObject[i] + o0);
  }
}

double doubleArea(const TriangleMesh& mesh, size_t tri) {
  const glm::uvec3 t = mesh.triangles[tri];
  const glm::dvec3 a(mesh.positions[t.x]), b(mesh.positions[t.y]), c(mesh.positions[t.z]);
  return glm::length(glm::cross(b - a, c - a));
}

Transform Transform::fromTrs(glm::vec3 translate, glm::vec3 rotateDeg, glm::vec3 scale) {
  const glm::mat4 rx = glm::rotate(glm::mat4(1.0f), glm::radians(rotateDeg.x), glm::vec3(1, 0, 0));
  const glm::mat4 ry = glm::rotate(glm::mat4(1.0f), glm::radians(rotateDeg.y), glm::vec3(0, 1, 0));
  const glm::mat4 rz = glm::rotate(glm::mat4(1.0f), glm::radians(rotateDeg.z), glm::vec3(0, 0, 1));
  Transform t;
  t.matrix = glm::translate(glm::mat4(1.0f), translate) * rz * ry * rx * glm::scale(glm::mat4(1.0f), scale);
  return t;
}

void applyTransform(TriangleMesh& mesh, const Transform& t, const std::string& what) {
  const glm::mat4& m = t.matrix;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) throw InputError(what + ": the transform holds a NaN or an infinity");
  if (m[0][3] != 0.0f || m[1][3] != 0.0f || m[2][3] != 0.0f || m[3][3] != 1.0f)
    throw InputError(what + ": the transform is not affine (its last row must be 0 0 0 1)");
  const glm::dmat3 linear(m);
  const double det = glm::determinant(linear);
  // Relative to the scale of the matrix: a map that flattens space to (nearly) a plane.
  const double norm = std::max({glm::length(linear[0]), glm::length(linear[1]), glm::length(linear[2])});
  if (!(std::abs(det) > 1e-12 * norm * norm * norm))
    throw InputError(what + ": the transform is singular (determinant " + std::to_string(det) + ")");
  const glm::dmat3 normalMatrix = glm::transpose(glm::inverse(linear));
  for (glm::vec3& p : mesh.positions) p = glm::vec3(m * glm::vec4(p, 1.0f));
  for (glm::vec3& n : mesh.normals) n = glm::vec3(glm::normalize(normalMatrix * glm::dvec3(n)));
  if (det < 0.0) {
    for (glm::uvec3& tri : mesh.triangles) std::swap(tri.y, tri.z);
    for (glm::uvec3& tri : mesh.triangleNormals) std::swap(tri.y, tri.z);
  }
}

TriangleMesh makePlane(glm::vec3 centre, glm::vec3 normal, glm::vec2 size, const std::string& what) {
  const float len = glm::length(normal);
  if (!std::isfinite(len) || len == 0.0f) throw InputError(what + ".normal: expected a non-zero direction");
  if (!(size.x > 0.0f && size.y > 0.0f && std::isfinite(size.x) && std::isfinite(size.y)))
    throw InputError(what + ".size: expected positive numbers");
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(centre[a])) throw InputError(what + ".center: expected finite numbers");
  const glm::vec3 n = normal / len;
  const glm::vec3 a = std::abs(n.z) > 1.0f - 1e-3f ? glm::vec3(1, 0, 0) : glm::vec3(0, 0, 1);
  const glm::vec3 u = glm::normalize(glm::cross(n, a));
  const glm::vec3 v = glm::cross(n, u);
  const glm::vec3 hu = 0.5f * size.x * u, hv = 0.5f * size.y * v;
  TriangleMesh mesh;
  // u x v = n: (-u,-v) -> (+u,-v) -> (+u,+v) runs counter-clockwise seen from n's side.
  mesh.positions = {centre - hu - hv, centre + hu - hv, centre + hu + hv, centre - hu + hv};
  mesh.normals = {n};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  mesh.triangleNormals = {glm::uvec3(0), glm::uvec3(0)};
  mesh.triangleObject = {0, 0};
  mesh.objects = {"plane"};
  return mesh;
}

}  // namespace plume::geo
