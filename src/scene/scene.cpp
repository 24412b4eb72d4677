#include "scene/scene.h"

#include "core/error.h"
#include "core/log.h"

#include <glm/geometric.hpp>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>

namespace plume {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// Strict reader for one JSON object: typed getters that name the key path in every error, and
// finish() rejects keys nobody asked for.
class ObjectReader {
 public:
  ObjectReader(const json& j, std::string file, std::string keyPath)
      : j_(j), file_(std::move(file)), path_(std::move(keyPath)) {
    if (!j_.is_object()) fail(path_, "expected an object");
  }

  [[noreturn]] void fail(const std::string& keyPath, const std::string& what) const {
    throw InputError(file_ + ": " + keyPath + ": " + what);
  }
  std::string keyPath(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

  const json* get(const std::string& key) {
    seen_.insert(key);
    auto it = j_.find(key);
    return it == j_.end() ? nullptr : &*it;
  }
  const json& require(const std::string& key) {
    const json* v = get(key);
    if (!v) fail(keyPath(key), "missing (required)");
    return *v;
  }

  double number(const std::string& key, double def, double lo, double hi, const char* rangeText) {
    const json* v = get(key);
    if (!v) return def;
    if (!v->is_number()) fail(keyPath(key), std::string("expected a number ") + rangeText);
    double d = v->get<double>();
    if (!std::isfinite(d) || d < lo || d > hi) fail(keyPath(key), std::string("expected a number ") + rangeText);
    return d;
  }
  int integer(const std::string& key, int def, int lo, int hi) {
    const json* v = get(key);
    if (!v) return def;
    double d = v->is_number() ? v->get<double>() : NAN;
    if (!std::isfinite(d) || d != std::floor(d) || d < lo || d > hi) {
      fail(keyPath(key), strf("expected an integer in [%d, %d]", lo, hi));
    }
    return int(d);
  }
  // 3 finite numbers, each in [lo, hi].
  glm::vec3 vec3(const std::string& key, glm::vec3 def, double lo, double hi, const char* rangeText) {
    const json* v = get(key);
    if (!v) return def;
    return vec3Of(*v, keyPath(key), lo, hi, rangeText);
  }
  glm::vec3 vec3Of(const json& v, const std::string& kp, double lo, double hi, const char* rangeText) const {
    std::string what = std::string("expected 3 numbers") + (rangeText[0] ? " " : "") + rangeText;
    if (!v.is_array() || v.size() != 3) fail(kp, what);
    glm::vec3 out;
    for (int i = 0; i < 3; ++i) {
      if (!v[i].is_number()) fail(kp, what);
      double d = v[i].get<double>();
      if (!std::isfinite(d) || d < lo || d > hi) fail(kp, what);
      out[i] = float(d);
    }
    return out;
  }
  std::string string(const std::string& key, const std::string& def) {
    const json* v = get(key);
    if (!v) return def;
    if (!v->is_string() || v->get<std::string>().empty()) fail(keyPath(key), "expected a non-empty string");
    return v->get<std::string>();
  }
  void finish() const {
    for (auto it = j_.begin(); it != j_.end(); ++it) {
      if (!seen_.count(it.key())) fail(keyPath(it.key()), "unknown key");
    }
  }

 private:
  const json& j_;
  std::string file_;
  std::string path_;
  std::set<std::string> seen_;
};

constexpr double kInf = 1e30;

std::string resolvePath(const std::string& dir, const std::string& p) {
  fs::path path(p);
  return path.is_absolute() || dir.empty() ? p : (fs::path(dir) / path).lexically_normal().string();
}

void readPoseFields(ObjectReader& r, CameraPose& pose) {
  pose.position = r.vec3("position", pose.position, -kInf, kInf, "");
  pose.lookAt = r.vec3("look_at", pose.lookAt, -kInf, kInf, "");
  pose.up = r.vec3("up", pose.up, -kInf, kInf, "");
  pose.fovY = float(r.number("fov_y", pose.fovY, 1e-3, 179.0, "in (0, 180) degrees"));
}

void checkPose(const ObjectReader& r, const CameraPose& pose, const std::string& kp) {
  glm::vec3 fwd = pose.lookAt - pose.position;
  if (glm::length(fwd) < 1e-8f) r.fail(kp + ".look_at", "must differ from position (zero-length view direction)");
  if (glm::length(pose.up) < 1e-8f) r.fail(kp + ".up", "zero-length direction");
  if (glm::length(glm::cross(glm::normalize(fwd), glm::normalize(pose.up))) < 1e-6f) {
    r.fail(kp + ".up", "parallel to the view direction");
  }
}

Camera parseCamera(const json& j, const std::string& file, int baseFrame) {
  ObjectReader r(j, file, "camera");
  Camera cam;
  cam.baseFrame = baseFrame;
  readPoseFields(r, cam.base);
  checkPose(r, cam.base, "camera");
  cam.width = r.integer("width", cam.width, 1, 16384);
  cam.height = r.integer("height", cam.height, 1, 16384);
  if (const json* keys = r.get("keys")) {
    if (!keys->is_array()) r.fail("camera.keys", "expected an array of {frame, position, look_at, ...}");
    CameraPose prev = cam.base;
    for (size_t i = 0; i < keys->size(); ++i) {
      std::string kp = strf("camera.keys[%zu]", i);
      ObjectReader kr((*keys)[i], file, kp);
      CameraKey key;
      key.frame = kr.integer("frame", 0, -10000000, 10000000);
      kr.require("frame");
      key.pose = prev;
      readPoseFields(kr, key.pose);
      checkPose(kr, key.pose, kp);
      kr.finish();
      if (!cam.keys.empty() && key.frame <= cam.keys.back().frame) {
        kr.fail(kp + ".frame", "keys must have increasing frame numbers");
      }
      cam.keys.push_back(key);
      prev = key.pose;
    }
  }
  r.finish();
  return cam;
}

Medium parseMedium(const json& j, const std::string& file, const std::string& dir, size_t index) {
  std::string kp = strf("media[%zu]", index);
  ObjectReader r(j, file, kp);
  Medium m;
  const json& vdb = r.require("vdb");
  if (!vdb.is_string() || vdb.get<std::string>().empty()) r.fail(kp + ".vdb", "expected a file path");
  m.vdb = resolvePath(dir, vdb.get<std::string>());
  if (!m.animated() && !fs::exists(m.vdb)) r.fail(kp + ".vdb", "file not found: " + m.vdb);
  m.densityGrid = r.string("density_grid", m.densityGrid);
  m.densityScale = float(r.number("density_scale", m.densityScale, 0.0, 1e12, "in [0, 1e12]"));
  m.albedo = r.vec3("albedo", m.albedo, 0.0, 1.0, "in [0,1]");
  m.g = float(r.number("g", m.g, -0.999999, 0.999999, "in (-1, 1)"));
  if (const json* e = r.get("emission")) {
    ObjectReader er(*e, file, kp + ".emission");
    Emission em;
    er.require("grid");
    em.grid = er.string("grid", "");
    em.scale = float(er.number("scale", 1.0, 0.0, 1e12, "in [0, 1e12]"));
    if (const json* b = er.get("blackbody")) {
      if (!b->is_boolean()) er.fail(kp + ".emission.blackbody", "expected true or false");
      em.blackbody = b->get<bool>();
    }
    const bool hasColor = er.get("color") != nullptr;
    em.color = er.vec3("color", em.color, 0.0, 1e12, "in [0, 1e12]");
    const bool hasTemperature = er.get("temperature_scale") || er.get("temperature_offset");
    em.temperatureScale = float(er.number("temperature_scale", 1.0, 0.0, 1e12, "in [0, 1e12] (kelvin per grid unit)"));
    em.temperatureOffset = float(er.number("temperature_offset", 0.0, -1e12, 1e12, "in [-1e12, 1e12]"));
    if (em.blackbody && hasColor) {
      er.fail(kp + ".emission.color", "a blackbody emission takes its colour from the temperature: remove \"color\" or \"blackbody\"");
    }
    if (!em.blackbody && hasTemperature) {
      er.fail(kp + ".emission", "\"temperature_scale\" and \"temperature_offset\" need \"blackbody\": true");
    }
    er.finish();
    m.emission = em;
  }
  r.finish();
  if (m.emission && m.albedo == glm::vec3(1.0f)) {
    logWarn(file + ": " + kp + ".emission: the albedo is 1 in every channel, so sigma_a = 0 and the medium emits nothing");
  }
  return m;
}

Light parseLight(const json& j, const std::string& file, const std::string& dir, size_t index) {
  std::string kp = strf("lights[%zu]", index);
  ObjectReader r(j, file, kp);
  Light l;
  const json& type = r.require("type");
  std::string t = type.is_string() ? type.get<std::string>() : "";
  if (t == "sun") {
    l.type = LightType::Sun;
    glm::vec3 d = r.vec3("to_light", l.toLight, -kInf, kInf, "");
    if (glm::length(d) < 1e-12f) r.fail(kp + ".to_light", "zero-length direction");
    l.toLight = glm::normalize(d);
    l.irradiance = r.vec3("irradiance", l.irradiance, 0.0, kInf, ">= 0");
    l.angularRadiusDeg = float(r.number("angular_radius", 0.0, 0.0, 45.0, "in [0, 45] degrees"));
  } else if (t == "point") {
    l.type = LightType::Point;
    l.position = r.vec3("position", l.position, -kInf, kInf, "");
    r.require("position");
    l.intensity = r.vec3("intensity", l.intensity, 0.0, kInf, ">= 0");
  } else if (t == "environment") {
    l.type = LightType::Environment;
    const bool hasRadiance = r.get("radiance") != nullptr;
    l.radiance = r.vec3("radiance", glm::vec3(0), 0.0, kInf, ">= 0");
    if (const json* map = r.get("map")) {
      if (!map->is_string() || map->get<std::string>().empty()) r.fail(kp + ".map", "expected a file path");
      // One source of radiance per light: a map is not tinted by `radiance` (use `scale`).
      if (hasRadiance) r.fail(kp + ".map", "give either \"radiance\" or \"map\", not both");
      l.map = resolvePath(dir, map->get<std::string>());
      if (!fs::exists(l.map)) r.fail(kp + ".map", "file not found: " + l.map);
    }
    glm::vec3 up = r.vec3("up", l.up, -kInf, kInf, "");
    if (glm::length(up) < 1e-12f) r.fail(kp + ".up", "zero-length direction");
    l.up = glm::normalize(up);
    l.rotateYDeg = float(r.number("rotate_y_deg", 0.0, -kInf, kInf, ""));
    l.scale = float(r.number("scale", 1.0, 0.0, kInf, ">= 0"));
  } else {
    r.fail(kp + ".type", "expected \"sun\", \"point\" or \"environment\"");
  }
  r.finish();
  return l;
}

// `scale`: a number (uniform) or 3 numbers, none 0.
glm::vec3 readScale(ObjectReader& r, const std::string& kp) {
  const json* v = r.get("scale");
  if (!v) return glm::vec3(1.0f);
  glm::vec3 s(1.0f);
  if (v->is_number()) s = glm::vec3(float(v->get<double>()));
  else s = r.vec3Of(*v, kp, -kInf, kInf, "");
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(s[a]) || s[a] == 0.0f) r.fail(kp, "expected a non-zero number or 3 non-zero numbers");
  return s;
}

glm::mat4 parseTransform(const json& j, const std::string& file, const std::string& kp) {
  ObjectReader r(j, file, kp);
  glm::mat4 m(1.0f);
  if (const json* mat = r.get("matrix")) {
    for (const char* k : {"translate", "rotate_deg", "scale"})
      if (j.contains(k)) r.fail(kp + ".matrix", std::string("give either \"matrix\" or translate/rotate_deg/scale, not both (found \"") + k + "\")");
    const std::string what = "expected 16 finite numbers (a 4x4 matrix, row-major, last row 0 0 0 1)";
    if (!mat->is_array() || mat->size() != 16) r.fail(kp + ".matrix", what);
    for (int row = 0; row < 4; ++row)
      for (int col = 0; col < 4; ++col) {
        const json& v = (*mat)[size_t(row * 4 + col)];
        if (!v.is_number() || !std::isfinite(v.get<double>())) r.fail(kp + ".matrix", what);
        m[col][row] = float(v.get<double>());
      }
    if (m[0][3] != 0.0f || m[1][3] != 0.0f || m[2][3] != 0.0f || m[3][3] != 1.0f)
      r.fail(kp + ".matrix", "not affine: the last row must be 0 0 0 1");
  } else {
    const glm::vec3 t = r.vec3("translate", glm::vec3(0.0f), -kInf, kInf, "");
    const glm::vec3 deg = r.vec3("rotate_deg", glm::vec3(0.0f), -kInf, kInf, "");
    const glm::vec3 s = readScale(r, kp + ".scale");
    // x' = T Rz Ry Rx S x, as geometry/mesh.h Transform::fromTrs (test_scene checks they agree).
    const glm::mat4 id(1.0f);
    m = glm::translate(id, t) * glm::rotate(id, glm::radians(deg.z), glm::vec3(0, 0, 1)) *
        glm::rotate(id, glm::radians(deg.y), glm::vec3(0, 1, 0)) * glm::rotate(id, glm::radians(deg.x), glm::vec3(1, 0, 0)) *
        glm::scale(id, s);
  }
  r.finish();
  const double det = glm::determinant(glm::dmat3(m));
  const glm::dmat3 l(m);
  const double norm = std::max({glm::length(l[0]), glm::length(l[1]), glm::length(l[2])});
  if (!(std::abs(det) > 1e-12 * norm * norm * norm)) r.fail(kp, "singular (the transform flattens the mesh)");
  return m;
}

Surface parseSurface(const json& j, const std::string& file, const std::string& dir, size_t index) {
  const std::string kp = strf("surfaces[%zu]", index);
  ObjectReader r(j, file, kp);
  Surface s;
  const json* obj = r.get("obj");
  const json* plane = r.get("plane");
  if (!obj == !plane) r.fail(kp, "expected exactly one of \"obj\" (a mesh file) or \"plane\"");
  if (obj) {
    s.obj = resolvePath(dir, r.string("obj", ""));
    if (!fs::exists(s.obj)) r.fail(kp + ".obj", "file not found: " + s.obj);
  } else {
    ObjectReader pr(*plane, file, kp + ".plane");
    SurfacePlane p;
    p.center = pr.vec3("center", p.center, -kInf, kInf, "");
    const glm::vec3 n = pr.vec3("normal", p.normal, -kInf, kInf, "");
    if (glm::length(n) < 1e-12f) pr.fail(kp + ".plane.normal", "zero-length direction");
    p.normal = glm::normalize(n);
    const json& size = pr.require("size");
    const std::string what = "expected a positive number or 2 positive numbers";
    if (size.is_number()) {
      p.size = glm::vec2(float(size.get<double>()));
    } else if (size.is_array() && size.size() == 2 && size[0].is_number() && size[1].is_number()) {
      p.size = glm::vec2(float(size[0].get<double>()), float(size[1].get<double>()));
    } else {
      pr.fail(kp + ".plane.size", what);
    }
    if (!(p.size.x > 0.0f && p.size.y > 0.0f && std::isfinite(p.size.x) && std::isfinite(p.size.y))) pr.fail(kp + ".plane.size", what);
    pr.finish();
    s.plane = p;
  }
  if (const json* t = r.get("transform")) s.transform = parseTransform(*t, file, kp + ".transform");
  const std::string material = r.string("material", "diffuse");
  s.emission = r.vec3("emission", s.emission, 0.0, kInf, ">= 0");
  if (material == "diffuse") {
    if (j.contains("roughness") || j.contains("f0"))
      r.fail(kp + (j.contains("roughness") ? ".roughness" : ".f0"), "belongs to \"material\": \"conductor\"");
    s.albedo = r.vec3("albedo", s.emits() ? glm::vec3(0.0f) : s.albedo, 0.0, 1.0, "in [0,1]");
  } else if (material == "conductor") {
    s.material = SurfaceMaterial::Conductor;
    if (j.contains("albedo")) r.fail(kp + ".albedo", "a conductor has no albedo: its colour is \"f0\"");
    r.require("roughness");
    r.require("f0");
    s.roughness = float(r.number("roughness", 0.0, 0.0, 1.0, "in [0, 1] (GGX alpha)"));
    s.f0 = r.vec3("f0", s.f0, 0.0, 1.0, "in [0,1]");
  } else {
    r.fail(kp + ".material", "expected \"diffuse\" or \"conductor\"");
  }
  r.finish();
  return s;
}

}  // namespace

bool hasFramePattern(const std::string& pattern) {
  static const std::regex re(R"(\{frame(:0?\d+)?\})");
  return std::regex_search(pattern, re);
}

std::string expandFramePattern(const std::string& pattern, int frame) {
  static const std::regex re(R"(\{frame(?::0?(\d+))?\})");
  std::string out;
  auto begin = std::sregex_iterator(pattern.begin(), pattern.end(), re);
  size_t last = 0;
  for (auto it = begin; it != std::sregex_iterator(); ++it) {
    const std::smatch& m = *it;
    out += pattern.substr(last, size_t(m.position()) - last);
    int width = m[1].matched ? std::stoi(m[1].str()) : 0;
    out += strf("%0*d", width, frame);
    last = size_t(m.position() + m.length());
  }
  return out + pattern.substr(last);
}

bool Medium::animated() const { return hasFramePattern(vdb); }
std::string Medium::vdbPath(int frame) const { return expandFramePattern(vdb, frame); }

bool Scene::hasEnvironment() const {
  return std::any_of(lights.begin(), lights.end(), [](const Light& l) { return l.type == LightType::Environment; });
}

CameraPose Camera::poseAt(double frame) const {
  if (keys.empty()) return base;
  // The base pose is a key at baseFrame unless a key sits on or before it.
  std::vector<CameraKey> all;
  if (keys.front().frame > baseFrame) all.push_back({baseFrame, base});
  all.insert(all.end(), keys.begin(), keys.end());
  if (frame <= all.front().frame) return all.front().pose;
  if (frame >= all.back().frame) return all.back().pose;
  for (size_t i = 0; i + 1 < all.size(); ++i) {
    const CameraKey& a = all[i];
    const CameraKey& b = all[i + 1];
    if (frame > b.frame) continue;
    float s = float((frame - a.frame) / double(b.frame - a.frame));
    CameraPose p;
    p.position = glm::mix(a.pose.position, b.pose.position, s);
    p.lookAt = glm::mix(a.pose.lookAt, b.pose.lookAt, s);
    p.up = glm::mix(a.pose.up, b.pose.up, s);
    p.fovY = glm::mix(a.pose.fovY, b.pose.fovY, s);
    return p;
  }
  return all.back().pose;
}

Scene parseScene(const json& doc, const std::string& path, const std::string& dir) {
  Scene scene;
  scene.path = path;
  scene.dir = dir;
  ObjectReader root(doc, path, "");
  // "render" first: the camera's base frame is the scene file's first frame.
  if (const json* render = root.get("render")) {
    ObjectReader rr(*render, path, "render");
    for (auto it = render->begin(); it != render->end(); ++it) {
      rr.get(it.key());
      if (!applyRenderSetting(scene.render, it.key(), it.value(), path, "render." + it.key())) {
        rr.fail("render." + it.key(), "unknown key");
      }
    }
  }
  scene.camera = parseCamera(root.require("camera"), path, scene.render.frameFirst);
  const json& media = root.require("media");
  if (!media.is_array()) root.fail("media", "expected an array of media");
  if (media.size() != 1) root.fail("media", "expected exactly one medium (several are not supported yet)");
  for (size_t i = 0; i < media.size(); ++i) scene.media.push_back(parseMedium(media[i], path, dir, i));
  if (const json* lights = root.get("lights")) {
    if (!lights->is_array()) root.fail("lights", "expected an array of lights");
    for (size_t i = 0; i < lights->size(); ++i) scene.lights.push_back(parseLight((*lights)[i], path, dir, i));
    if (std::count_if(scene.lights.begin(), scene.lights.end(), [](const Light& l) { return !l.map.empty(); }) > 1) {
      root.fail("lights", "at most one environment light may have a map");
    }
  }
  if (const json* surfaces = root.get("surfaces")) {
    if (!surfaces->is_array()) root.fail("surfaces", "expected an array of surfaces");
    for (size_t i = 0; i < surfaces->size(); ++i) scene.surfaces.push_back(parseSurface((*surfaces)[i], path, dir, i));
  }
  root.finish();
  return scene;
}

Scene loadScene(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open scene file");
  json doc = json::parse(in, nullptr, false);
  if (doc.is_discarded()) {
    // Re-parse with exceptions for a message with the byte position.
    std::ifstream again(path);
    try {
      doc = json::parse(again);
    } catch (const json::parse_error& e) {
      throw InputError(path + ": invalid JSON: " + e.what());
    }
    throw InputError(path + ": invalid JSON");
  }
  std::string dir = fs::path(path).parent_path().string();
  return parseScene(doc, path, dir);
}

}  // namespace plume
