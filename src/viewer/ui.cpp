#include "viewer/ui.h"

#include "core/log.h"
#include "scene/settings.h"

#include <glm/glm.hpp>
#include <imgui.h>

#include <cmath>
#include <initializer_list>
#include <map>
#include <string>

namespace plume::viewer {
namespace {

void drawTimings(const ViewStats& stats) {
  ImGui::Text("%s", stats.device.c_str());
  ImGui::Text("%s  %dx%d", stats.renderer.c_str(), stats.width, stats.height);
  ImGui::Text("%.1f fps  %.2f ms/frame  %d spp", stats.fps, stats.frameMs, stats.samples);
  for (const auto& [name, ms] : stats.passes) ImGui::Text("  %-28s %7.2f ms", name.c_str(), ms);
}

void drawTransport(ViewState& s, UiRequests& req) {
  const RenderSettings& rs = s.scene.render;
  if (ImGui::Button(s.playing ? "Pause" : "Play")) s.playing = !s.playing;
  ImGui::SameLine();
  if (ImGui::Button("<")) req.step = -1;
  ImGui::SameLine();
  if (ImGui::Button(">")) req.step = +1;
  ImGui::SameLine();
  int f = s.frame;
  ImGui::SetNextItemWidth(-1);
  if (rs.frameLast > rs.frameFirst && ImGui::SliderInt("##frame", &f, rs.frameFirst, rs.frameLast, "frame %d")) {
    req.step = f - s.frame;
  }
}

const SettingDesc* findSetting(const std::string& key) {
  for (const SettingDesc& d : renderSettingsTable()) {
    if (key == d.key) return &d;
  }
  return nullptr;
}

// One radio button per render.mode of the settings table.
void drawModes(ViewState& s, UiRequests& req) {
  const SettingDesc* d = findSetting("mode");
  if (!d) return;
  for (const std::string& mode : d->choices) {
    if (ImGui::RadioButton(mode.c_str(), s.scene.render.mode == mode)) {
      s.scene.render.mode = mode;
      req.rebuildRenderer = true;
    }
    ImGui::SameLine();
  }
  ImGui::NewLine();
}

int intSetting(const RenderSettings& rs, const SettingDesc& d) {
  if (auto* m = std::get_if<int RenderSettings::*>(&d.member)) return rs.*(*m);
  if (auto* m64 = std::get_if<int64_t RenderSettings::*>(&d.member)) return int(std::min<int64_t>(rs.*(*m64), 0x7fffffff));
  return 0;
}

// On/off switch for count settings where 0 means off (temporal reuse = the history cap, spatial
// reuse = the rounds and those where nothing changed): on while any of them is positive;
// switching off sets those to 0, switching on restores the values they had when last on
// (`remembered`, which holds a start value for the first key).
void drawReuseToggle(ViewState& s, UiRequests& req, const char* label, std::initializer_list<const char*> keys,
                     std::map<std::string, int>& remembered) {
  bool on = false;
  for (const char* key : keys) {
    const SettingDesc* d = findSetting(key);
    const int value = d ? intSetting(s.scene.render, *d) : 0;
    if (value > 0) remembered[key] = value, on = true;
  }
  if (ImGui::Checkbox(label, &on)) {
    for (const char* key : keys) {
      const SettingDesc* d = findSetting(key);
      if (!d) continue;
      if (!on && intSetting(s.scene.render, *d) > 0) applyRenderSettingText(s.scene.render, key, "0");
      if (on && remembered.count(key)) applyRenderSettingText(s.scene.render, key, std::to_string(remembered[key]));
    }
    req.rebuildRenderer = true;
  }
}

// One render setting from the table: a slider or field for numbers, a combo for choices.
void drawSetting(ViewState& s, UiRequests& req, const SettingDesc& d) {
  {
    const std::string key = d.key;
    if (auto* ms = std::get_if<std::string RenderSettings::*>(&d.member)) {
      if (d.choices.empty()) return;
      const std::string current = s.scene.render.*(*ms);
      if (ImGui::BeginCombo(key.c_str(), current.c_str())) {
        for (const std::string& c : d.choices) {
          if (ImGui::Selectable(c.c_str(), c == current) && c != current) {
            applyRenderSettingText(s.scene.render, key, c);
            req.rebuildRenderer = true;
          }
        }
        ImGui::EndCombo();
      }
      if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", d.help);
      return;
    }
    int v = intSetting(s.scene.render, d);
    const int lo = int(std::max(d.min, -2147483648.0)), hi = int(std::min(d.max, 2147483647.0));
    if (hi - lo <= 256) ImGui::SliderInt(key.c_str(), &v, lo, hi);
    else ImGui::InputInt(key.c_str(), &v);
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", d.help);
    if (ImGui::IsItemDeactivatedAfterEdit() || (ImGui::IsItemEdited() && !ImGui::IsItemActive())) {
      const std::string text = std::to_string(glm::clamp(v, lo, hi));
      applyRenderSettingText(s.scene.render, key, text);
      req.rebuildRenderer = true;
    }
  }
}

// Every render setting from the table except mode (radio buttons) and spp (per-frame control).
void drawSettingsTable(ViewState& s, UiRequests& req, const ViewStats& stats) {
  auto used = [&](const std::string& key) { return !stats.usesSetting || stats.usesSetting(key); };
  const bool restirOn = used("restir_history_cap");
  static std::map<std::string, int> remembered = {{"restir_history_cap", 20}, {"restir_rounds", 1}};
  ImGui::BeginDisabled(!restirOn);
  drawReuseToggle(s, req, "temporal reuse", {"restir_history_cap"}, remembered);
  ImGui::SameLine();
  drawReuseToggle(s, req, "spatial reuse", {"restir_rounds", "restir_rounds_static"}, remembered);
  ImGui::EndDisabled();
  if (!restirOn) ImGui::TextDisabled("restir_* settings act in the ReSTIR modes");
  for (const SettingDesc& d : renderSettingsTable()) {
    const std::string key = d.key;
    if (key == "mode" || key == "spp") continue;
    const bool disabled = !used(key);
    ImGui::BeginDisabled(disabled);
    drawSetting(s, req, d);
    ImGui::EndDisabled();
  }
}

void drawMedium(ViewState& s, UiRequests& req) {
  Medium& m = s.scene.medium();
  if (ImGui::SliderFloat("density scale", &m.densityScale, 0.0f, 200.0f, "%.2f", ImGuiSliderFlags_Logarithmic)) req.restart = true;
  if (ImGui::ColorEdit3("albedo", &m.albedo.x, ImGuiColorEditFlags_Float)) req.restart = true;
  if (ImGui::SliderFloat("g", &m.g, -0.99f, 0.99f)) req.restart = true;
  for (size_t i = 0; i < s.scene.lights.size(); ++i) {
    Light& l = s.scene.lights[i];
    if (l.type != LightType::Sun) continue;
    // Direction towards the sun as azimuth / elevation (y up); lights are uploaded when built.
    const glm::vec3 d = glm::normalize(l.toLight);
    float elev = glm::degrees(std::asin(glm::clamp(d.y, -1.0f, 1.0f)));
    float azim = glm::degrees(std::atan2(d.x, d.z));
    ImGui::PushID(int(i));
    bool edited = ImGui::SliderFloat("sun azimuth", &azim, -180.0f, 180.0f, "%.0f deg");
    bool done = ImGui::IsItemDeactivatedAfterEdit();
    edited |= ImGui::SliderFloat("sun elevation", &elev, -89.0f, 89.0f, "%.0f deg");
    done |= ImGui::IsItemDeactivatedAfterEdit();
    ImGui::PopID();
    if (edited) {
      const float e = glm::radians(elev), a = glm::radians(azim);
      l.toLight = glm::vec3(std::cos(e) * std::sin(a), std::sin(e), std::cos(e) * std::cos(a));
    }
    if (done) req.rebuildRenderer = true;
  }
}

}  // namespace

UiRequests drawUi(ViewState& s, const ViewStats& stats) {
  UiRequests req;
  ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowBgAlpha(0.75f);
  ImGui::Begin("plume view  (H hides)", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
  drawTimings(stats);
  ImGui::Separator();
  drawTransport(s, req);
  // The settings start folded: open, the panel covered ~40% of a 1280x720 window (the image's
  // left part) and ran past its bottom edge, and on lavapipe it cost ~2.5 ms a frame more to draw.
  if (ImGui::CollapsingHeader("Estimator")) {
    drawModes(s, req);
    drawSettingsTable(s, req, stats);
    ImGui::SliderInt("spp per frame", &s.sppPerFrame, 1, 64);
    if (ImGui::InputInt("max spp", &s.maxSamples)) s.maxSamples = std::max(1, s.maxSamples);
  }
  if (ImGui::CollapsingHeader("Medium and light")) drawMedium(s, req);
  ImGui::SliderFloat("exposure", &s.exposure, -6.0f, 6.0f, "%.1f stops");
  if (ImGui::Button("Screenshot (S)")) req.screenshot = true;
  ImGui::SameLine();
  if (ImGui::Button("Reset camera (R)")) req.resetCamera = true;
  ImGui::TextDisabled("drag: orbit  right/middle drag: pan  wheel: zoom");
  ImGui::TextDisabled("space: play  arrows: step  S: screenshot  H: hide");
  if (!s.status.empty()) ImGui::TextWrapped("%s", s.status.c_str());
  ImGui::End();
  return req;
}

}  // namespace plume::viewer
