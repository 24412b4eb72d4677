// Command-line flags generated from the render settings table (scene/settings.h): every
// `render` key of the scene can be overridden as --key (underscores become dashes).
#pragma once

#include "scene/settings.h"

#include <CLI/CLI.hpp>

#include <map>
#include <memory>
#include <string>

namespace plume {

using SettingOverrides = std::map<std::string, std::string>;  // key -> text from the command line

void addSettingOptions(CLI::App& cmd, SettingOverrides& overrides);
void applyOverrides(RenderSettings& settings, const SettingOverrides& overrides);  // throws InputError

}  // namespace plume
