#include "core/error.h"
#include "render/estimator.h"
#include "scene/scene.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

using namespace plume;
using nlohmann::json;

namespace {

json minimalScene() {
  return json::parse(R"({
    "camera": {"position": [0, 1, 4], "look_at": [0, 0.5, 0], "fov_y": 40, "width": 64, "height": 32},
    "media": [{"vdb": "smoke/smoke_{frame:04}.vdb", "density_scale": 8, "albedo": [0.9, 0.9, 0.9], "g": 0.3}],
    "lights": [{"type": "sun", "to_light": [0, 2, 0], "irradiance": [3, 3, 3]}],
    "render": {"max_bounces": 4, "spp": 8, "seed": 7, "frames": [1, 24]}
  })");
}

std::string errorOf(const json& doc) {
  try {
    parseScene(doc, "scene.json", "/nonexistent");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Scene, ParsesTheDesignExampleKeys) {
  Scene s = parseScene(minimalScene(), "scene.json", "/data");
  EXPECT_EQ(s.camera.width, 64);
  EXPECT_EQ(s.media.at(0).vdb, "/data/smoke/smoke_{frame:04}.vdb");
  EXPECT_EQ(s.media[0].vdbPath(7), "/data/smoke/smoke_0007.vdb");
  EXPECT_FLOAT_EQ(s.lights.at(0).toLight.y, 1.0f);  // normalised
  EXPECT_EQ(s.render.maxBounces, 4);
  EXPECT_EQ(s.render.frameLast, 24);
  EXPECT_EQ(s.render.mode, "pt");  // default
}

TEST(Scene, ErrorsNameTheKeyPath) {
  json d = minimalScene();
  d["media"][0]["albedo"] = {0.5, 2.0, 0.5};
  EXPECT_EQ(errorOf(d), "scene.json: media[0].albedo: expected 3 numbers in [0,1]");
  d = minimalScene();
  d["media"][0]["g"] = 1.0;
  EXPECT_NE(errorOf(d).find("media[0].g"), std::string::npos);
  d = minimalScene();
  d["media"][0]["density_scale"] = -1;
  EXPECT_NE(errorOf(d).find("media[0].density_scale"), std::string::npos);
  d = minimalScene();
  d["lights"][0]["to_light"] = {0, 0, 0};
  EXPECT_EQ(errorOf(d), "scene.json: lights[0].to_light: zero-length direction");
  d = minimalScene();
  d["camera"]["colour"] = 1;
  EXPECT_EQ(errorOf(d), "scene.json: camera.colour: unknown key");
  d = minimalScene();
  d["render"]["spp"] = "many";
  EXPECT_NE(errorOf(d).find("render.spp"), std::string::npos);
  d = minimalScene();
  d["render"]["mode"] = "magic";
  EXPECT_NE(errorOf(d).find("render.mode: expected one of pt, restir, restir-biased"), std::string::npos);
  d = minimalScene();
  d["camera"]["look_at"] = {0, 1, 4};
  EXPECT_NE(errorOf(d).find("camera.look_at"), std::string::npos);
}

TEST(Scene, CameraKeysInterpolateAndHold) {
  json d = minimalScene();
  d["camera"]["keys"] = json::array({{{"frame", 11}, {"position", {2, 1, 4}}}});
  Scene s = parseScene(d, "scene.json", "/data");
  EXPECT_FLOAT_EQ(s.camera.poseAt(1).position.x, 0.0f);
  EXPECT_FLOAT_EQ(s.camera.poseAt(6).position.x, 1.0f);
  EXPECT_FLOAT_EQ(s.camera.poseAt(30).position.x, 2.0f);
  EXPECT_FLOAT_EQ(s.camera.poseAt(6).lookAt.y, 0.5f);  // inherited from the base pose
}

TEST(Scene, CommandLineOverridesGoThroughTheSettingsTable) {
  RenderSettings r;
  EXPECT_TRUE(applyRenderSettingText(r, "spp", "64"));
  EXPECT_EQ(r.spp, 64);
  EXPECT_TRUE(applyRenderSettingText(r, "frames", "3-9"));
  EXPECT_EQ(r.frameFirst, 3);
  EXPECT_EQ(r.frameLast, 9);
  EXPECT_TRUE(applyRenderSettingText(r, "mode", "restir"));
  EXPECT_EQ(r.mode, "restir");
  EXPECT_THROW(applyRenderSettingText(r, "spp", "0"), InputError);
  EXPECT_FALSE(applyRenderSettingText(r, "nonsense", "1"));
}

TEST(Scene, FramePatterns) {
  EXPECT_EQ(expandFramePattern("a_{frame:04}.vdb", 12), "a_0012.vdb");
  EXPECT_EQ(expandFramePattern("a_{frame}.vdb", 12), "a_12.vdb");
  EXPECT_FALSE(hasFramePattern("plain.vdb"));
}

// Environment maps (DESIGN §2, §9): the keys, `up` normalised, the map resolved against the
// scene's folder; radiance with a map, a zero `up` and two maps are refused naming the key.
TEST(Scene, EnvironmentMapKeys) {
  json doc = minimalScene();
  const std::string dir = PLUME_SOURCE_DIR "/volumes/smoke";
  doc["lights"].push_back({{"type", "environment"}, {"map", "../sky/sky.exr"}, {"up", {0, 0, 2}},
                           {"rotate_y_deg", -30}, {"scale", 2.5}});
  Scene s = parseScene(doc, "scene.json", dir);
  const Light& l = s.lights.at(1);
  EXPECT_EQ(l.map, PLUME_SOURCE_DIR "/volumes/sky/sky.exr");
  EXPECT_EQ(l.up, glm::vec3(0, 0, 1));
  EXPECT_FLOAT_EQ(l.rotateYDeg, -30.0f);
  EXPECT_FLOAT_EQ(l.scale, 2.5f);
  EXPECT_EQ(s.lights.at(0).map, "");
  auto errorIn = [&](const json& d) {
    try {
      parseScene(d, "scene.json", dir);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  json both = doc;
  both["lights"][1]["radiance"] = {1, 1, 1};
  EXPECT_NE(errorIn(both).find("scene.json: lights[1].map: give either"), std::string::npos) << errorIn(both);
  json zeroUp = doc;
  zeroUp["lights"][1]["up"] = {0, 0, 0};
  EXPECT_NE(errorIn(zeroUp).find("lights[1].up: zero-length"), std::string::npos) << errorIn(zeroUp);
  json two = doc;
  two["lights"].push_back(doc["lights"][1]);
  EXPECT_NE(errorIn(two).find("lights: at most one environment light may have a map"), std::string::npos) << errorIn(two);
}

// What each estimator's render key holds and the viewer greys out: the path tracer none of the
// restir_* settings; ReSTIR all of them, but the shift only where the scene has surfaces (without
// them it changes nothing, so frames rendered before the setting existed stay valid).
TEST(Scene, EstimatorsUseTheSettingsTheirPixelsDependOn) {
  Scene bare;
  Scene withSurfaces;
  withSurfaces.surfaces.push_back(Surface{});
  for (const Scene* s : {&bare, &withSurfaces}) {
    const auto& pt = estimatorTraits(EstimatorKind::PathTracer).usesSetting;
    EXPECT_TRUE(pt(*s, "max_bounces"));
    EXPECT_FALSE(pt(*s, "restir_shift"));
    EXPECT_FALSE(pt(*s, "restir_candidates"));
    for (EstimatorKind k : {EstimatorKind::Restir, EstimatorKind::RestirBiased}) {
      const auto& restir = estimatorTraits(k).usesSetting;
      EXPECT_TRUE(restir(*s, "max_bounces"));
      EXPECT_TRUE(restir(*s, "restir_candidates"));
      EXPECT_EQ(restir(*s, "restir_shift"), s == &withSurfaces);
    }
  }
}
