#include "support/meshes.h"

#include <cmath>

namespace plume::test {
namespace {

void finish(geo::TriangleMesh& m, const char* name) {
  m.triangleNormals.assign(m.triangles.size(), glm::uvec3(geo::kNoNormal));
  m.triangleObject.assign(m.triangles.size(), 0u);
  m.objects = {name};
}

}  // namespace

geo::TriangleMesh makeCube(float h) {
  geo::TriangleMesh m;
  for (int i = 0; i < 8; ++i) m.positions.push_back(glm::vec3(i & 1 ? h : -h, i & 2 ? h : -h, i & 4 ? h : -h));
  // Faces as quads (a, b, c, d) counter-clockwise from outside, split along a-c.
  const int quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& q : quads) {
    m.triangles.push_back(glm::uvec3(q[0], q[1], q[2]));
    m.triangles.push_back(glm::uvec3(q[0], q[2], q[3]));
  }
  finish(m, "cube");
  return m;
}

geo::TriangleMesh makeSphere(glm::vec3 centre, float radius, int rings, int segments) {
  geo::TriangleMesh m;
  const double pi = 3.14159265358979323846;
  m.positions.push_back(centre + glm::vec3(0, radius, 0));  // north pole: 0
  for (int i = 1; i < rings; ++i) {
    const double theta = pi * i / rings;
    for (int j = 0; j < segments; ++j) {
      const double phi = 2.0 * pi * j / segments;
      m.positions.push_back(centre + radius * glm::vec3(float(std::sin(theta) * std::cos(phi)), float(std::cos(theta)),
                                                        float(-std::sin(theta) * std::sin(phi))));
    }
  }
  const uint32_t south = uint32_t(m.positions.size());
  m.positions.push_back(centre - glm::vec3(0, radius, 0));
  auto at = [&](int ring, int seg) { return uint32_t(1 + (ring - 1) * segments + (seg % segments)); };
  // Seen from outside, phi increases counter-clockwise around +Y... with z = -sin(phi) it runs
  // clockwise seen from above (+Y), i.e. counter-clockwise seen from outside along a band.
  for (int j = 0; j < segments; ++j) {
    m.triangles.push_back(glm::uvec3(0, at(1, j), at(1, j + 1)));
    m.triangles.push_back(glm::uvec3(south, at(rings - 1, j + 1), at(rings - 1, j)));
  }
  for (int i = 1; i + 1 < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      m.triangles.push_back(glm::uvec3(at(i, j), at(i + 1, j), at(i + 1, j + 1)));
      m.triangles.push_back(glm::uvec3(at(i, j), at(i + 1, j + 1), at(i, j + 1)));
    }
  }
  finish(m, "sphere");
  return m;
}

geo::TriangleMesh makeTorus(glm::vec3 centre, float R, float r, int nu, int nv) {
  geo::TriangleMesh m;
  const double pi = 3.14159265358979323846;
  for (int i = 0; i < nu; ++i) {
    const double u = 2.0 * pi * i / nu;
    for (int j = 0; j < nv; ++j) {
      const double v = 2.0 * pi * j / nv;
      const double rr = R + r * std::cos(v);
      m.positions.push_back(centre + glm::vec3(float(rr * std::cos(u)), float(r * std::sin(v)), float(-rr * std::sin(u))));
    }
  }
  auto at = [&](int i, int j) { return uint32_t((i % nu) * nv + (j % nv)); };
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      m.triangles.push_back(glm::uvec3(at(i, j), at(i + 1, j), at(i + 1, j + 1)));
      m.triangles.push_back(glm::uvec3(at(i, j), at(i + 1, j + 1), at(i, j + 1)));
    }
  }
  finish(m, "torus");
  return m;
}

}  // namespace plume::test
