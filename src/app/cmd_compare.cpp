#include "app/commands.h"

namespace plume {
void addCompareCommand(CLI::App& app, Action& action) {}  // placeholder: the stats work fills it in
}  // namespace plume
