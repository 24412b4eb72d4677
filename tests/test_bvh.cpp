// The host side of the surfaces (geometry/): the flattened BVH is a well-formed tree over exactly
// the input triangles (every triangle referenced, boxes nested, leaves partition the triangle
// array, stats add up), with and without spatial splits; the built-in plane faces its normal
// (counter-clockwise seen from it); transforms compose as documented (T R S, R = Rz Ry Rx), carry
// normals by the inverse transpose and keep the front side under a mirror; bad transforms are
// input errors. The traversal against Embree is in test_gpu_bvh.cpp.
#include "core/error.h"
#include "geometry/bvh.h"
#include "geometry/mesh.h"
#include "support/meshes.h"

#include <cstring>
#include <gtest/gtest.h>

#include <vector>

using namespace plume;
namespace sh = plume::shared;

namespace {

bool contains(glm::vec3 lo, glm::vec3 hi, glm::vec3 p) { return glm::all(glm::lessThanEqual(lo, p)) && glm::all(glm::lessThanEqual(p, hi)); }

// Checks the tree and returns how often each input triangle is referenced.
std::vector<int> checkTree(const geo::TriangleMesh& mesh, const geo::FlatBvh& bvh, bool splits) {
  std::vector<int> refs(mesh.triangles.size(), 0), nodeSeen(bvh.nodes.size(), 0), triSeen(bvh.triangles.size(), 0);
  struct Item {
    uint32_t node;
    glm::vec3 lo, hi;
    int depth;
  };
  std::vector<Item> stack{{0u, glm::vec3(-1e30f), glm::vec3(1e30f), 1}};
  int depth = 0;
  size_t leaves = 0;
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    EXPECT_LT(it.node, bvh.nodes.size());
    if (it.node >= bvh.nodes.size()) break;
    EXPECT_EQ(nodeSeen[it.node]++, 0) << "node " << it.node << " reached twice";
    depth = std::max(depth, it.depth);
    const sh::BvhNode& n = bvh.nodes[it.node];
    for (int c = 0; c < 2; ++c) {
      const uint32_t ref = c ? n.ref1 : n.ref0, count = c ? n.count1 : n.count0;
      const glm::vec3 lo = c ? n.lo1 : n.lo0, hi = c ? n.hi1 : n.hi0;
      if (ref == sh::BVH_NONE) continue;
      EXPECT_TRUE(contains(it.lo, it.hi, lo) && contains(it.lo, it.hi, hi)) << "child box outside its parent's, node " << it.node;
      if (count == 0) {
        stack.push_back({ref, lo, hi, it.depth + 1});
        continue;
      }
      ++leaves;
      EXPECT_LE(count, sh::BVH_MAX_LEAF_SIZE);
      for (uint32_t i = ref; i < ref + count && i < bvh.triangles.size(); ++i) {
        ++triSeen[i];
        const sh::BvhTriangle& t = bvh.triangles[i];
        EXPECT_LT(t.prim, mesh.triangles.size());
        if (t.prim >= mesh.triangles.size()) continue;
        ++refs[t.prim];
        const glm::uvec3 v = mesh.triangles[t.prim];
        EXPECT_TRUE(t.v0 == mesh.positions[v.x] && t.v1 == mesh.positions[v.y] && t.v2 == mesh.positions[v.z]) << "triangle " << i;
        if (!splits) {
          EXPECT_TRUE(contains(lo, hi, t.v0) && contains(lo, hi, t.v1) && contains(lo, hi, t.v2)) << "triangle outside its leaf";
        } else {  // a split reference: its leaf box overlaps the triangle's box
          const glm::vec3 tlo = glm::min(t.v0, glm::min(t.v1, t.v2)), thi = glm::max(t.v0, glm::max(t.v1, t.v2));
          EXPECT_TRUE(glm::all(glm::lessThanEqual(glm::max(lo, tlo), glm::min(hi, thi)))) << "leaf box misses its triangle";
        }
      }
    }
  }
  for (size_t i = 0; i < nodeSeen.size(); ++i) EXPECT_EQ(nodeSeen[i], 1) << "node " << i;
  for (size_t i = 0; i < triSeen.size(); ++i) EXPECT_EQ(triSeen[i], 1) << "triangle slot " << i << ": leaves must partition the array";
  EXPECT_EQ(bvh.stats.depth, depth);
  EXPECT_EQ(bvh.stats.leaves, leaves);
  EXPECT_EQ(bvh.stats.nodes, bvh.nodes.size());
  EXPECT_EQ(bvh.stats.references, bvh.triangles.size());
  // The device's texels (shared/bvh.h): a header, 4 per node, 3 per triangle, a zero texel; the
  // header names triangle 0's texel, and the nodes and triangles are their structs' bytes.
  const std::vector<glm::uvec4> texels = geo::bvhDeviceTexels(bvh);
  EXPECT_EQ(bvh.stats.bytes, 16 + bvh.nodes.size() * 64 + bvh.triangles.size() * 48 + 16);
  EXPECT_EQ(texels.size() * 16, bvh.stats.bytes);
  EXPECT_EQ(texels[0].x, 1 + 4 * bvh.nodes.size());
  EXPECT_EQ(std::memcmp(&texels[1], bvh.nodes.data(), bvh.nodes.size() * 64), 0);
  if (!bvh.triangles.empty()) EXPECT_EQ(std::memcmp(&texels[texels[0].x], bvh.triangles.data(), bvh.triangles.size() * 48), 0);
  EXPECT_EQ(texels.back(), glm::uvec4(0u));
  return refs;
}

geo::TriangleMesh sceneMesh() {
  geo::TriangleMesh m = geo::makePlane(glm::vec3(0, -1, 0), glm::vec3(0, 1, 0), glm::vec2(20.0f, 20.0f), "plane");
  m.append(test::makeSphere(glm::vec3(0.0f), 1.0f, 16, 32));
  m.append(test::makeTorus(glm::vec3(2.0f, 0.0f, 0.0f), 0.8f, 0.2f, 32, 16));
  return m;
}

double signedVolume(const geo::TriangleMesh& m) {
  double v = 0.0;
  for (const glm::uvec3& t : m.triangles)
    v += glm::dot(glm::dvec3(m.positions[t.x]), glm::cross(glm::dvec3(m.positions[t.y]), glm::dvec3(m.positions[t.z]))) / 6.0;
  return v;
}

glm::dvec3 geometricNormal(const geo::TriangleMesh& m, size_t tri) {
  const glm::uvec3 t = m.triangles[tri];
  return glm::normalize(glm::cross(glm::dvec3(m.positions[t.y] - m.positions[t.x]), glm::dvec3(m.positions[t.z] - m.positions[t.x])));
}

}  // namespace

TEST(Bvh, FlattenedTreeIsWellFormed) {
  for (bool splits : {false, true}) {
    for (const geo::TriangleMesh& mesh : {test::makeCube(), test::makeSphere(glm::vec3(0.5f), 2.0f, 32, 64), sceneMesh()}) {
      geo::BvhOptions options;
      options.spatialSplits = splits;
      const geo::FlatBvh bvh = geo::buildBvh(mesh, options);
      const std::vector<int> refs = checkTree(mesh, bvh, splits);
      for (size_t i = 0; i < refs.size(); ++i) {
        if (splits) EXPECT_GE(refs[i], 1) << "triangle " << i;
        else EXPECT_EQ(refs[i], 1) << "triangle " << i;
      }
      EXPECT_LE(bvh.stats.depth, sh::BVH_STACK_SIZE);
    }
  }
}

TEST(Bvh, SpatialSplitsCutLongTriangles) {
  // Where the SAH gains by cutting a triangle between leaves (the objects' triangles beside a
  // tilted ground), the spatial split build references it more than once; the plain binned build
  // never does.
  geo::TriangleMesh mesh = geo::makePlane(glm::vec3(0, -1, 0), glm::vec3(0.3f, 1.0f, 0.2f), glm::vec2(20.0f, 20.0f), "plane");
  mesh.append(test::makeSphere(glm::vec3(0.0f), 1.0f, 16, 32));
  mesh.append(test::makeTorus(glm::vec3(2.0f, 0.0f, 0.0f), 0.8f, 0.2f, 32, 16));
  const geo::FlatBvh bvh = geo::buildBvh(mesh);
  checkTree(mesh, bvh, true);
  EXPECT_GT(bvh.stats.references, mesh.triangles.size());
  geo::BvhOptions plain;
  plain.spatialSplits = false;
  EXPECT_EQ(geo::buildBvh(mesh, plain).stats.references, mesh.triangles.size());
}

TEST(Bvh, EmptyAndSingleLeafTrees) {
  const geo::FlatBvh empty = geo::buildBvh(geo::TriangleMesh{});
  ASSERT_EQ(empty.nodes.size(), 1u);
  EXPECT_EQ(empty.nodes[0].ref0, sh::BVH_NONE);
  EXPECT_EQ(empty.nodes[0].ref1, sh::BVH_NONE);
  EXPECT_TRUE(empty.triangles.empty());
  const geo::EmbreeScene none{geo::TriangleMesh{}};
  EXPECT_EQ(none.intersect(glm::vec3(0.0f), glm::vec3(0, 0, 1), 0.0f, 1e30f).prim, sh::BVH_NONE);
  EXPECT_FALSE(none.occluded(glm::vec3(0.0f), glm::vec3(0, 0, 1), 0.0f, 1e30f));
  const geo::TriangleMesh plane = geo::makePlane(glm::vec3(0.0f), glm::vec3(0, 0, 1), glm::vec2(1.0f, 2.0f), "plane");
  const geo::FlatBvh one = geo::buildBvh(plane);
  ASSERT_EQ(one.nodes.size(), 1u);
  EXPECT_EQ(one.nodes[0].count0, 2u);
  EXPECT_EQ(one.nodes[0].ref1, sh::BVH_NONE);
  checkTree(plane, one, false);
  const geo::EmbreeScene embree(plane);  // the plane faces +Z at the origin, 1 x 2
  const sh::BvhHit hit = embree.intersect(glm::vec3(0.1f, 0.2f, 2.0f), glm::vec3(0, 0, -1), 0.0f, 1e30f);
  EXPECT_FLOAT_EQ(hit.t, 2.0f);
  EXPECT_NE(hit.prim, sh::BVH_NONE);
  EXPECT_TRUE(embree.occluded(glm::vec3(0.1f, 0.2f, -2.0f), glm::vec3(0, 0, 1), 0.0f, 3.0f)) << "both sides";
  EXPECT_FALSE(embree.occluded(glm::vec3(0.1f, 0.2f, -2.0f), glm::vec3(0, 0, 1), 0.0f, 1.5f)) << "tMax";
}

TEST(Mesh, GeneratedMeshesFaceOutwards) {
  EXPECT_NEAR(signedVolume(test::makeCube(1.0f)), 8.0, 1e-6);
  EXPECT_NEAR(signedVolume(test::makeSphere(glm::vec3(0.0f), 1.0f, 64, 128)), 4.18879, 0.01);
  EXPECT_NEAR(signedVolume(test::makeTorus(glm::vec3(0.0f), 1.0f, 0.25f, 128, 64)), 2.0 * 9.8696 * 0.25 * 0.25, 0.01);
}

TEST(Mesh, PlaneFacesItsNormal) {
  for (glm::vec3 n : {glm::vec3(0, 1, 0), glm::vec3(0, 0, -1), glm::vec3(1, 2, -0.5f), glm::vec3(0, 0, 3)}) {
    const geo::TriangleMesh p = geo::makePlane(glm::vec3(1, 2, 3), n, glm::vec2(4.0f, 2.0f), "plane");
    ASSERT_EQ(p.triangles.size(), 2u);
    double area = 0.0;
    for (size_t t = 0; t < 2; ++t) {
      EXPECT_NEAR(glm::dot(geometricNormal(p, t), glm::normalize(glm::dvec3(n))), 1.0, 1e-6) << "counter-clockwise seen from n";
      area += 0.5 * geo::doubleArea(p, t);
      EXPECT_NEAR(glm::dot(glm::dvec3(p.normals[p.triangleNormals[t].x]), glm::normalize(glm::dvec3(n))), 1.0, 1e-6);
    }
    EXPECT_NEAR(area, 8.0, 1e-5);
    glm::vec3 c(0.0f);
    for (const glm::vec3& v : p.positions) c += 0.25f * v;
    EXPECT_NEAR(glm::length(c - glm::vec3(1, 2, 3)), 0.0f, 1e-5f);
  }
  // The ground: size.x along +X, size.y along Z.
  const geo::TriangleMesh g = geo::makePlane(glm::vec3(0.0f), glm::vec3(0, 1, 0), glm::vec2(4.0f, 2.0f), "plane");
  EXPECT_FLOAT_EQ(std::abs(g.positions[0].x), 2.0f);
  EXPECT_FLOAT_EQ(std::abs(g.positions[0].z), 1.0f);
  EXPECT_THROW(geo::makePlane(glm::vec3(0.0f), glm::vec3(0.0f), glm::vec2(1.0f), "plane"), InputError);
  EXPECT_THROW(geo::makePlane(glm::vec3(0.0f), glm::vec3(0, 1, 0), glm::vec2(1.0f, 0.0f), "plane"), InputError);
  EXPECT_THROW(geo::makePlane(glm::vec3(NAN), glm::vec3(0, 1, 0), glm::vec2(1.0f), "plane"), InputError);
}

TEST(Mesh, TransformsComposeAsDocumented) {
  auto apply = [](const geo::Transform& t, glm::vec3 p) { return glm::vec3(t.matrix * glm::vec4(p, 1.0f)); };
  auto near = [](glm::vec3 a, glm::vec3 b) { return glm::length(a - b) < 1e-5f; };
  // R = Rz Ry Rx: X first. (0,1,0) -> Rx(90) -> (0,0,1) -> Ry(90) -> (1,0,0).
  EXPECT_TRUE(near(apply(geo::Transform::fromTrs(glm::vec3(0.0f), glm::vec3(90, 90, 0), glm::vec3(1.0f)), glm::vec3(0, 1, 0)), glm::vec3(1, 0, 0)));
  EXPECT_TRUE(near(apply(geo::Transform::fromTrs(glm::vec3(0.0f), glm::vec3(0, 0, 90), glm::vec3(1.0f)), glm::vec3(1, 0, 0)), glm::vec3(0, 1, 0)));
  // Scale, then rotate, then translate.
  EXPECT_TRUE(near(apply(geo::Transform::fromTrs(glm::vec3(1, 2, 3), glm::vec3(0, 0, 90), glm::vec3(2, 1, 1)), glm::vec3(1, 0, 0)), glm::vec3(1, 4, 3)));
}

TEST(Mesh, NormalsByTheInverseTransposeAndMirrorsKeepTheFront) {
  const geo::TriangleMesh base = geo::makePlane(glm::vec3(0.0f), glm::normalize(glm::vec3(1, 1, 0)), glm::vec2(1.0f), "plane");
  for (glm::vec3 scale : {glm::vec3(1, 3, 1), glm::vec3(-1, 1, 1), glm::vec3(2, -0.5f, -1)}) {
    geo::TriangleMesh m = base;
    geo::applyTransform(m, geo::Transform::fromTrs(glm::vec3(0.5f), glm::vec3(10, 20, 30), scale), "surfaces[0].transform");
    const glm::dvec3 shading(m.normals[0]);
    EXPECT_NEAR(glm::length(shading), 1.0, 1e-6);
    for (size_t t = 0; t < 2; ++t)  // the shading normal stays perpendicular and on the front side
      EXPECT_NEAR(glm::dot(geometricNormal(m, t), shading), 1.0, 1e-5) << "scale " << scale.x << " " << scale.y << " " << scale.z;
  }
}

TEST(Mesh, BadTransformsAreInputErrors) {
  geo::TriangleMesh m = test::makeCube();
  auto message = [&](const geo::Transform& t) -> std::string {
    try {
      geo::applyTransform(m, t, "surfaces[1].transform");
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(message(geo::Transform::fromTrs(glm::vec3(0.0f), glm::vec3(0.0f), glm::vec3(1, 0, 1))).rfind("surfaces[1].transform: the transform is singular", 0), 0u);
  EXPECT_EQ(message(geo::Transform::fromTrs(glm::vec3(NAN), glm::vec3(0.0f), glm::vec3(1.0f))), "surfaces[1].transform: the transform holds a NaN or an infinity");
  geo::Transform projective;
  projective.matrix[0][3] = 0.5f;
  EXPECT_EQ(message(projective), "surfaces[1].transform: the transform is not affine (its last row must be 0 0 0 1)");
}
