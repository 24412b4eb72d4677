// Wavefront OBJ loading (geometry/obj.h, DESIGN §9 surfaces[].obj): the face forms i, i/t, i//n,
// i/t/n, negative indices, polygons fan-triangulated, objects and groups; bad input is an
// InputError naming the file and the line; degenerate triangles are dropped and counted.
#include "core/error.h"
#include "geometry/obj.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

using namespace plume;
using namespace plume::geo;

namespace {

ObjMesh parse(const std::string& text) {
  std::istringstream in(text);
  return parseObj(in, "test.obj");
}

// The InputError's message for `text` ("" when it parses).
std::string errorOf(const std::string& text) {
  try {
    parse(text);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

const char* kQuad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";

}  // namespace

TEST(Obj, TriangleAndPolygons) {
  const ObjMesh m = parse(std::string(kQuad) + "v 0.5 1.5 0\nf 1 2 3\nf 1 2 3 4\nf 1 2 3 5 4\n");
  EXPECT_EQ(m.stats.faces, 3u);
  EXPECT_EQ(m.stats.triangles, 1u + 2u + 3u);
  EXPECT_EQ(m.stats.degenerate, 0u);
  ASSERT_EQ(m.mesh.triangles.size(), 6u);
  // Fans from the first vertex, winding kept.
  EXPECT_EQ(m.mesh.triangles[1], glm::uvec3(0, 1, 2));
  EXPECT_EQ(m.mesh.triangles[2], glm::uvec3(0, 2, 3));
  EXPECT_EQ(m.mesh.triangles[5], glm::uvec3(0, 4, 3));
  EXPECT_FALSE(m.mesh.hasNormals(0));
}

TEST(Obj, VertexForms) {
  const std::string head = std::string(kQuad) + "vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 2\nvn 0 0 -1\n";
  const ObjMesh a = parse(head + "f 1/1 2/2 3/3\n");
  EXPECT_FALSE(a.mesh.hasNormals(0));
  const ObjMesh b = parse(head + "f 1//1 2//1 3//2\n");
  ASSERT_TRUE(b.mesh.hasNormals(0));
  EXPECT_EQ(b.mesh.triangleNormals[0], glm::uvec3(0, 0, 1));
  EXPECT_FLOAT_EQ(b.mesh.normals[0].z, 1.0f) << "normals are normalised";
  const ObjMesh c = parse(head + "f 1/1/2 2/2/2 3/3/1\n");
  EXPECT_EQ(c.mesh.triangleNormals[0], glm::uvec3(1, 1, 0));
  EXPECT_EQ(c.mesh.triangles[0], glm::uvec3(0, 1, 2));
}

TEST(Obj, NegativeIndicesCountBack) {
  const ObjMesh m = parse(std::string(kQuad) + "vn 0 0 1\nf -4//-1 -3//-1 -2//-1\nv 5 5 5\nf -1 -5 -4\n");
  ASSERT_EQ(m.mesh.triangles.size(), 2u);
  EXPECT_EQ(m.mesh.triangles[0], glm::uvec3(0, 1, 2));
  EXPECT_EQ(m.mesh.triangles[1], glm::uvec3(4, 0, 1));
}

TEST(Obj, ObjectsAndGroups) {
  const ObjMesh m = parse(std::string(kQuad) + "# a comment\nf 1 2 3\no lamp\ns 1\nusemtl glow\nf 1 3 4\ng ground base\r\nf 2 3 4\n");
  ASSERT_EQ(m.mesh.objects.size(), 3u);
  EXPECT_EQ(m.mesh.objects[0], "");
  EXPECT_EQ(m.mesh.objects[1], "lamp");
  EXPECT_EQ(m.mesh.objects[2], "ground base");
  EXPECT_EQ(m.mesh.triangleObject, (std::vector<uint32_t>{0, 1, 2}));
}

TEST(Obj, DegenerateTrianglesAreDroppedAndCounted) {
  // A repeated index, three collinear points, and a quad whose fan has one zero-area triangle.
  const ObjMesh m = parse(std::string(kQuad) + "v 2 0 0\nf 1 2 2\nf 1 2 5\nf 1 2 5 3\nf 1 2 3\n");
  EXPECT_EQ(m.stats.degenerate, 3u);
  EXPECT_EQ(m.stats.triangles, 2u);
  EXPECT_EQ(m.mesh.triangles.size(), 2u);
  EXPECT_EQ(m.mesh.triangleObject.size(), 2u);
  EXPECT_EQ(m.mesh.triangleNormals.size(), 2u);
}

TEST(Obj, ErrorsNameTheFileAndLine) {
  EXPECT_EQ(errorOf(std::string(kQuad) + "f 1 2 3\n"), "");
  EXPECT_EQ(errorOf("v 0 0 0\nv 1 2\n"), "test.obj:2: `v` expects 3 to 6 numbers, got 2");
  EXPECT_EQ(errorOf("v 0 0 zero\n"), "test.obj:1: expected a number, got 'zero'");
  EXPECT_EQ(errorOf(std::string(kQuad) + "f 1 2 5\n"), "test.obj:5: position index 5 out of range (4 positions defined so far)");
  EXPECT_EQ(errorOf(std::string(kQuad) + "f 1 2 0\n"), "test.obj:5: position index 0 out of range (4 positions defined so far)");
  EXPECT_EQ(errorOf(std::string(kQuad) + "f 1 2 -5\n"), "test.obj:5: position index -5 out of range (4 positions defined so far)");
  EXPECT_EQ(errorOf(std::string(kQuad) + "f 1//1 2//1 3//1\n"), "test.obj:5: normal index 1 out of range (0 normals defined so far)");
  EXPECT_EQ(errorOf(std::string(kQuad) + "f 1/1 2/1 3/1\n"), "test.obj:5: texture coordinate index 1 out of range (0 texture coordinates defined so far)");
  EXPECT_EQ(errorOf(std::string(kQuad) + "f 1 2\n"), "test.obj:5: a face needs at least 3 vertices, got 2");
  EXPECT_EQ(errorOf(std::string(kQuad) + "vn 0 0 1\nf 1 2//1 3\n"), "test.obj:6: face vertices mix the forms i, i/t, i//n, i/t/n");
  EXPECT_EQ(errorOf(std::string(kQuad) + "f 1/2/3/4 2 3\n"), "test.obj:5: malformed face vertex '1/2/3/4'");
  EXPECT_EQ(errorOf(std::string(kQuad) + "f 1 2 x\n"), "test.obj:5: malformed position index 'x'");
  EXPECT_EQ(errorOf("\n\nbogus 1 2\n"), "test.obj:3: unknown statement 'bogus'");
  EXPECT_EQ(errorOf("vn 0 0 0\n"), "test.obj:1: `vn` of zero length");
}

TEST(Obj, NonFiniteCoordinatesAreErrors) {
  EXPECT_EQ(errorOf("v 0 0 0\nv nan 0 0\n"), "test.obj:2: NaN or infinite coordinate 'nan'");
  EXPECT_EQ(errorOf("v 0 -inf 0\n"), "test.obj:1: NaN or infinite coordinate '-inf'");
  EXPECT_EQ(errorOf("v 0 0 1e39\n"), "test.obj:1: coordinate '1e39' is out of float range");
  EXPECT_EQ(errorOf("vn 0 NaN 1\n"), "test.obj:1: NaN or infinite coordinate 'NaN'");
}

TEST(Obj, LoadsAFileAndNamesAMissingOne) {
  const std::string dir = test::outputDir("obj");
  const std::string path = dir + "/quad.obj";
  {
    std::ofstream f(path);
    f << kQuad << "f 1 2 3 4\n";
  }
  const ObjMesh m = loadObj(path);
  EXPECT_EQ(m.stats.triangles, 2u);
  try {
    loadObj(dir + "/missing.obj");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), dir + "/missing.obj: cannot open the OBJ file");
  }
  {
    std::ofstream f(path);
    f << kQuad << "f 1 2 3 9\n";
  }
  try {
    loadObj(path);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), path + ":5: position index 9 out of range (4 positions defined so far)");
  }
}
