// DESIGN §9 surfaces[]: an OBJ or the built-in plane, an optional transform (translate /
// rotate_deg / scale, or a 4x4 matrix), a material (diffuse albedo, or conductor with roughness
// and f0) and an optional emission; errors name the key. The transform's composition equals
// geometry's Transform::fromTrs. Which commands render surfaces: tests/bad_inputs/cases.json
// (ReSTIR refuses them), tests/test_gpu_surfaces.cpp, tests/test_reference_surfaces.cpp.
#include "core/error.h"
#include "geometry/mesh.h"
#include "geometry/scene_mesh.h"
#include "scene/scene.h"
#include "support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>

using namespace plume;
using nlohmann::json;

namespace {

// A folder with ground.obj for the scenes below.
std::string sceneDir() {
  static const std::string dir = [] {
    const std::string d = test::outputDir("scene_surfaces");
    std::ofstream(d + "/ground.obj") << "v -1 0 1\nv 1 0 1\nv 1 0 -1\nv -1 0 -1\nf 1 2 3 4\n";
    std::ofstream(d + "/sliver.obj") << "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\nf 1 1 4\n";
    std::ofstream(d + "/empty.obj") << "# nothing\nv 0 0 0\n";
    std::ofstream(d + "/broken.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n";
    return d;
  }();
  return dir;
}

json sceneWith(const json& surfaces) {
  json d = json::parse(R"({
    "camera": {"position": [0, 1, 4], "look_at": [0, 0.5, 0]},
    "media": [{"vdb": "smoke_{frame:04}.vdb"}],
    "render": {"frames": [1, 2]}
  })");
  d["surfaces"] = surfaces;
  return d;
}

Scene parse(const json& surfaces) { return parseScene(sceneWith(surfaces), "scene.json", sceneDir()); }

std::string errorOf(const json& surfaces) {
  try {
    parse(surfaces);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(SceneSurfaces, ParsesEveryForm) {
  const Scene s = parse(json::parse(R"([
    {"obj": "ground.obj", "albedo": [0.2, 0.3, 0.4]},
    {"plane": {"center": [1, 2, 3], "normal": [0, 2, 0], "size": [4, 5]}, "material": "conductor", "roughness": 0.3, "f0": [0.9, 0.6, 0.2]},
    {"plane": {"size": 3}, "emission": [4, 3.5, 3], "transform": {"translate": [1, 0, 0], "rotate_deg": [0, 90, 0], "scale": 2}},
    {"obj": "ground.obj", "transform": {"matrix": [1, 0, 0, 5,  0, 2, 0, 6,  0, 0, 1, 7,  0, 0, 0, 1]}}
  ])"));
  ASSERT_EQ(s.surfaces.size(), 4u);
  EXPECT_EQ(s.surfaces[0].obj, sceneDir() + "/ground.obj");
  EXPECT_EQ(s.surfaces[0].material, SurfaceMaterial::Diffuse);
  EXPECT_EQ(s.surfaces[0].albedo, glm::vec3(0.2f, 0.3f, 0.4f));
  EXPECT_FALSE(s.surfaces[0].emits());
  ASSERT_TRUE(s.surfaces[1].plane.has_value());
  EXPECT_TRUE(s.surfaces[1].obj.empty());
  EXPECT_EQ(s.surfaces[1].plane->normal, glm::vec3(0, 1, 0));  // normalised
  EXPECT_EQ(s.surfaces[1].plane->size, glm::vec2(4, 5));
  EXPECT_EQ(s.surfaces[1].plane->center, glm::vec3(1, 2, 3));
  EXPECT_EQ(s.surfaces[1].material, SurfaceMaterial::Conductor);
  EXPECT_FLOAT_EQ(s.surfaces[1].roughness, 0.3f);
  EXPECT_EQ(s.surfaces[1].f0, glm::vec3(0.9f, 0.6f, 0.2f));
  EXPECT_EQ(s.surfaces[2].plane->size, glm::vec2(3, 3));
  EXPECT_EQ(s.surfaces[2].plane->normal, glm::vec3(0, 1, 0));  // the default: the ground
  EXPECT_TRUE(s.surfaces[2].emits());
  EXPECT_EQ(s.surfaces[2].albedo, glm::vec3(0.0f)) << "an emitter is black unless given an albedo";
  const glm::mat4 m = *s.surfaces[3].transform;
  EXPECT_EQ(m[3], glm::vec4(5, 6, 7, 1)) << "row-major in the file: the last column is the translation";
  EXPECT_EQ(m[1][1], 2.0f);
}

TEST(SceneSurfaces, TransformMatchesGeometry) {
  const Scene s = parse(json::parse(R"([{"obj": "ground.obj", "transform": {"translate": [1, -2, 3], "rotate_deg": [10, 20, 30], "scale": [1, 2, 3]}}])"));
  const glm::mat4 g = geo::Transform::fromTrs(glm::vec3(1, -2, 3), glm::vec3(10, 20, 30), glm::vec3(1, 2, 3)).matrix;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) EXPECT_NEAR((*s.surfaces[0].transform)[c][r], g[c][r], 1e-6f) << c << " " << r;
}

TEST(SceneSurfaces, ErrorsNameTheKey) {
  auto e = [](const char* text) { return errorOf(json::parse(text)); };
  EXPECT_EQ(e(R"({"obj": "ground.obj"})"), "scene.json: surfaces: expected an array of surfaces");
  EXPECT_EQ(e(R"([{"albedo": [1, 1, 1]}])"), "scene.json: surfaces[0]: expected exactly one of \"obj\" (a mesh file) or \"plane\"");
  EXPECT_EQ(e(R"([{"obj": "ground.obj", "plane": {"size": 1}}])"), "scene.json: surfaces[0]: expected exactly one of \"obj\" (a mesh file) or \"plane\"");
  EXPECT_EQ(e(R"([{"obj": "nope.obj"}])"), "scene.json: surfaces[0].obj: file not found: " + sceneDir() + "/nope.obj");
  EXPECT_EQ(e(R"([{"obj": "ground.obj"}, {"plane": {"normal": [0, 0, 0], "size": 1}}])"), "scene.json: surfaces[1].plane.normal: zero-length direction");
  EXPECT_EQ(e(R"([{"plane": {"size": [1, -1]}}])"), "scene.json: surfaces[0].plane.size: expected a positive number or 2 positive numbers");
  EXPECT_EQ(e(R"([{"plane": {"size": [1, 2, 3]}}])"), "scene.json: surfaces[0].plane.size: expected a positive number or 2 positive numbers");
  EXPECT_EQ(e(R"([{"plane": {}}])"), "scene.json: surfaces[0].plane.size: missing (required)");
  EXPECT_EQ(e(R"([{"plane": {"size": 1, "centre": [0, 0, 0]}}])"), "scene.json: surfaces[0].plane.centre: unknown key");
  EXPECT_EQ(e(R"([{"obj": "ground.obj", "transform": {"scale": 0}}])"), "scene.json: surfaces[0].transform.scale: expected a non-zero number or 3 non-zero numbers");
  EXPECT_EQ(e(R"([{"obj": "ground.obj", "transform": {"rotate": [0, 1, 0]}}])"), "scene.json: surfaces[0].transform.rotate: unknown key");
  EXPECT_EQ(e(R"([{"obj": "ground.obj", "transform": {"matrix": [1, 2, 3]}}])"), "scene.json: surfaces[0].transform.matrix: expected 16 finite numbers (a 4x4 matrix, row-major, last row 0 0 0 1)");
  EXPECT_EQ(e(R"([{"obj": "ground.obj", "transform": {"matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,1,1]}}])"), "scene.json: surfaces[0].transform.matrix: not affine: the last row must be 0 0 0 1");
  EXPECT_EQ(e(R"([{"obj": "ground.obj", "transform": {"matrix": [1,0,0,0, 0,1,0,0, 0,0,0,0, 0,0,0,1]}}])"), "scene.json: surfaces[0].transform: singular (the transform flattens the mesh)");
  EXPECT_EQ(e(R"([{"obj": "ground.obj", "transform": {"matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1], "translate": [1, 0, 0]}}])"), "scene.json: surfaces[0].transform.matrix: give either \"matrix\" or translate/rotate_deg/scale, not both (found \"translate\")");
  EXPECT_EQ(e(R"([{"obj": "ground.obj", "material": "plastic"}])"), "scene.json: surfaces[0].material: expected \"diffuse\" or \"conductor\"");
  EXPECT_EQ(e(R"([{"obj": "ground.obj", "roughness": 0.2}])"), "scene.json: surfaces[0].roughness: belongs to \"material\": \"conductor\"");
  EXPECT_EQ(e(R"([{"obj": "ground.obj", "material": "conductor", "f0": [1, 1, 1]}])"), "scene.json: surfaces[0].roughness: missing (required)");
  EXPECT_EQ(e(R"([{"obj": "ground.obj", "material": "conductor", "roughness": 2, "f0": [1, 1, 1]}])"), "scene.json: surfaces[0].roughness: expected a number in [0, 1] (GGX alpha)");
  EXPECT_EQ(e(R"([{"obj": "ground.obj", "material": "conductor", "roughness": 0.1, "f0": [1, 1, 1], "albedo": [1, 1, 1]}])"), "scene.json: surfaces[0].albedo: a conductor has no albedo: its colour is \"f0\"");
  EXPECT_EQ(e(R"([{"obj": "ground.obj", "material": "conductor", "roughness": 0.1, "f0": [1, 1.5, 1]}])"), "scene.json: surfaces[0].f0: expected 3 numbers in [0,1]");
  EXPECT_EQ(e(R"([{"obj": "ground.obj", "emission": [1, -1, 1]}])"), "scene.json: surfaces[0].emission: expected 3 numbers >= 0");
  EXPECT_EQ(e(R"([{"obj": "ground.obj", "albedo": [1, 1, 2]}])"), "scene.json: surfaces[0].albedo: expected 3 numbers in [0,1]");
  EXPECT_EQ(e(R"([{"obj": "ground.obj", "colour": [1, 1, 1]}])"), "scene.json: surfaces[0].colour: unknown key");
}

TEST(SceneSurfaces, LoadedIntoOneWorldSpaceMesh) {
  const Scene s = parse(json::parse(R"([
    {"plane": {"center": [0, 1, 0], "size": 2}},
    {"obj": "ground.obj", "transform": {"translate": [0, 5, 0], "scale": 2}},
    {"obj": "sliver.obj", "material": "conductor", "roughness": 0.2, "f0": [1, 1, 1]}
  ])"));
  const geo::SceneMesh m = geo::loadSceneSurfaces(s);
  ASSERT_EQ(m.mesh.triangles.size(), 2u + 2u + 1u);
  EXPECT_EQ(m.triangleSurface, (std::vector<uint32_t>{0, 0, 1, 1, 2}));
  EXPECT_EQ(m.degenerate, (std::vector<size_t>{0, 0, 2}));
  // The OBJ quad, scaled by 2 and lifted by 5: its corners at (+-2, 5, +-2).
  for (size_t t = 2; t < 4; ++t)
    for (int k = 0; k < 3; ++k) {
      const glm::vec3 p = m.mesh.positions[m.mesh.triangles[t][k]];
      EXPECT_FLOAT_EQ(std::abs(p.x), 2.0f);
      EXPECT_FLOAT_EQ(p.y, 5.0f);
      EXPECT_FLOAT_EQ(std::abs(p.z), 2.0f);
    }
  // The plane at y = 1 facing +Y.
  for (int k = 0; k < 3; ++k) EXPECT_FLOAT_EQ(m.mesh.positions[m.mesh.triangles[0][k]].y, 1.0f);
}

TEST(SceneSurfaces, LoadErrorsNameTheFileOrTheKey) {
  auto loadError = [](const char* text) -> std::string {
    try {
      geo::loadSceneSurfaces(parse(json::parse(text)));
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(loadError(R"([{"obj": "broken.obj"}])"), sceneDir() + "/broken.obj:4: position index 4 out of range (3 positions defined so far)");
  EXPECT_EQ(loadError(R"([{"plane": {"size": 1}}, {"obj": "empty.obj"}])"), "scene.json: surfaces[1]: no triangles (" + sceneDir() + "/empty.obj)");
  EXPECT_EQ(loadError(R"([{"obj": "ground.obj"}])"), "");
}
