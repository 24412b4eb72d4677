#include "app/commands.h"

namespace plume {
void addInfoCommand(CLI::App& app, Action& action) {}  // placeholder: the media work fills it in
}  // namespace plume
