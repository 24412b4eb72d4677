#include "scene/render_key.h"

#include "core/log.h"
#include "scene/settings.h"

#include <charconv>
#include <filesystem>
#include <variant>

namespace plume {

std::string RenderKey::text() const {
  std::string s;
  for (const auto& [name, value] : entries) s += (s.empty() ? "" : "; ") + name + "=" + value;
  return s;
}

std::string RenderKey::differences(const std::string& stored) const {
  if (stored == text()) return "";
  // The stored text split back into entries; only for the message (the match compares texts), so
  // a value holding "; " at worst makes the message list one entry too many.
  std::vector<std::pair<std::string, std::string>> old;
  for (size_t pos = 0; pos <= stored.size();) {
    size_t end = stored.find("; ", pos);
    if (end == std::string::npos) end = stored.size();
    const std::string item = stored.substr(pos, end - pos);
    const size_t eq = item.find('=');
    if (eq != std::string::npos) old.emplace_back(item.substr(0, eq), item.substr(eq + 1));
    pos = end + 2;
  }
  auto valueIn = [](const auto& list, const std::string& name) -> std::string {
    for (const auto& [n, v] : list) {
      if (n == name) return v;
    }
    return "(unset)";
  };
  std::string diff;
  auto note = [&](const std::string& name, const std::string& was, const std::string& now) {
    if (was != now) diff += (diff.empty() ? "" : ", ") + name + " " + was + " -> " + now;
  };
  for (const auto& [name, value] : entries) note(name, valueIn(old, name), value);
  for (const auto& [name, value] : old) {
    if (valueIn(entries, name) == "(unset)") note(name, value, "(unset)");
  }
  return diff.empty() ? "the same entries in another order" : diff;
}

namespace {

// The shortest text that reads back as the same float.
std::string num(float v) {
  char buf[32];
  return std::string(buf, std::to_chars(buf, buf + sizeof buf, v).ptr);
}
std::string vec(const glm::vec3& v) { return num(v.x) + " " + num(v.y) + " " + num(v.z); }

// A path named by the scene file, relative to the scene's folder where it lies below it, so the
// key does not change with the working directory a job starts in.
std::string sceneRelative(const Scene& scene, const std::string& path) {
  const std::string rel = std::filesystem::path(path).lexically_relative(scene.dir.empty() ? "." : scene.dir).string();
  return rel.empty() ? path : rel;
}

std::string lightText(const Scene& scene, const Light& l) {
  switch (l.type) {
    case LightType::Sun:
      return "sun to_light " + vec(l.toLight) + ", irradiance " + vec(l.irradiance) + ", angular_radius " +
             num(l.angularRadiusDeg);
    case LightType::Point: return "point position " + vec(l.position) + ", intensity " + vec(l.intensity);
    case LightType::Environment:
      return "environment radiance " + vec(l.radiance) + ", scale " + num(l.scale) + ", map " +
             (l.map.empty() ? "none" : sceneRelative(scene, l.map)) + ", up " + vec(l.up) + ", rotate_y " + num(l.rotateYDeg);
  }
  return "?";
}

}  // namespace

RenderKey sceneRenderKey(const Scene& scene, int frame, const std::function<bool(const std::string&)>& uses) {
  RenderKey key;
  const Camera& cam = scene.camera;
  const CameraPose pose = cam.poseAt(frame);
  key.add("camera.width", std::to_string(cam.width));
  key.add("camera.height", std::to_string(cam.height));
  key.add("camera.position", vec(pose.position));
  key.add("camera.look_at", vec(pose.lookAt));
  key.add("camera.up", vec(pose.up));
  key.add("camera.fov_y", num(pose.fovY));
  for (size_t i = 0; i < scene.media.size(); ++i) {
    const Medium& m = scene.media[i];
    const std::string p = strf("media[%zu].", i);
    key.add(p + "vdb", sceneRelative(scene, m.vdbPath(frame)));
    key.add(p + "density_grid", m.densityGrid);
    key.add(p + "density_scale", num(m.densityScale));
    key.add(p + "albedo", vec(m.albedo));
    key.add(p + "g", num(m.g));
    std::string emission = "none";
    if (const auto& e = m.emission) {
      emission = e->grid + " x " + num(e->scale) +
                 (e->blackbody ? " blackbody " + num(e->temperatureScale) + " " + num(e->temperatureOffset)
                               : " color " + num(e->color.x) + " " + num(e->color.y) + " " + num(e->color.z));
    }
    key.add(p + "emission", emission);
  }
  for (size_t i = 0; i < scene.lights.size(); ++i) key.add(strf("lights[%zu]", i), lightText(scene, scene.lights[i]));
  for (size_t i = 0; i < scene.surfaces.size(); ++i) {
    const Surface& s = scene.surfaces[i];
    std::string text = s.plane ? "plane " + vec(s.plane->center) + " normal " + vec(s.plane->normal) + " size " +
                                     num(s.plane->size.x) + " " + num(s.plane->size.y)
                               : sceneRelative(scene, s.obj);
    if (s.transform) {
      text += ", transform";
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) text += " " + num((*s.transform)[c][r]);
    }
    text += s.material == SurfaceMaterial::Conductor ? ", conductor roughness " + num(s.roughness) + " f0 " + vec(s.f0)
                                                     : ", albedo " + vec(s.albedo);
    if (s.emits()) text += ", emission " + vec(s.emission);
    key.add(strf("surfaces[%zu]", i), text);
  }
  // render.*: every setting of the table (frames, the range, is not one of them).
  for (const SettingDesc& d : renderSettingsTable()) {
    if (!uses(d.key)) continue;
    std::string value;
    if (auto* m = std::get_if<int RenderSettings::*>(&d.member)) value = std::to_string(scene.render.*(*m));
    if (auto* m64 = std::get_if<int64_t RenderSettings::*>(&d.member)) value = std::to_string(scene.render.*(*m64));
    if (auto* ms = std::get_if<std::string RenderSettings::*>(&d.member)) value = scene.render.*(*ms);
    key.add(d.key, value);
  }
  return key;
}

}  // namespace plume
