#include "app/settings_cli.h"

#include "core/error.h"

namespace plume {

void addSettingOptions(CLI::App& cmd, SettingOverrides& overrides) {
  auto add = [&](const std::string& key, const std::string& help) {
    cmd.add_option_function<std::string>(
        cliFlagFor(key), [&overrides, key](const std::string& v) { overrides[key] = v; }, help);
  };
  for (const SettingDesc& d : renderSettingsTable()) add(d.key, std::string(d.help) + " (render." + d.key + ")");
  add("frames", "frame range FIRST-LAST or a single frame (render.frames)");
}

void applyOverrides(RenderSettings& settings, const SettingOverrides& overrides) {
  for (const auto& [key, text] : overrides) {
    if (!applyRenderSettingText(settings, key, text)) throw InputError("command line: " + cliFlagFor(key) + ": unknown setting");
  }
}

}  // namespace plume
