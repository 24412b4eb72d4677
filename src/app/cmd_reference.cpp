#include "app/commands.h"

namespace plume {
void addReferenceCommand(CLI::App& app, Action& action) {}  // placeholder
}  // namespace plume
