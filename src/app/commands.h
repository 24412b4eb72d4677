// One file per command; each adds its CLI11 subcommand and sets `action` when it is chosen.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>

namespace plume {

using Action = std::function<int()>;

void addInfoCommand(CLI::App& app, Action& action);       // cmd_info.cpp
void addCompareCommand(CLI::App& app, Action& action);    // cmd_compare.cpp
void addReferenceCommand(CLI::App& app, Action& action);  // cmd_reference.cpp
void addRenderCommand(CLI::App& app, Action& action);     // cmd_render.cpp
void addBenchCommand(CLI::App& app, Action& action);      // cmd_bench.cpp
void addViewCommand(CLI::App& app, Action& action);       // cmd_view.cpp

}  // namespace plume
