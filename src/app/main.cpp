// plume: thin main. Commands live in cmd_*.cpp; errors map to exit codes (core/error.h).
#include "app/commands.h"
#include "core/error.h"

#include <cstdio>
#include <exception>
#include <new>

int main(int argc, char** argv) {
  using namespace plume;
  CLI::App app{"Plume: volumetric ReSTIR renderer for OpenVDB smoke, clouds and fire"};
  app.set_version_flag("--version", std::string("plume ") + PLUME_VERSION);
  app.require_subcommand(1);
  Action action;
  addInfoCommand(app, action);
  addRenderCommand(app, action);
  addViewCommand(app, action);
  addReferenceCommand(app, action);
  addCompareCommand(app, action);
  addBenchCommand(app, action);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "plume: %s\n", e.what());
    return kExitBadInput;
  }
  try {
    return action ? action() : kExitOk;
  } catch (const InputError& e) {
    std::fprintf(stderr, "plume: error: %s\n", e.what());
    return kExitBadInput;
  } catch (const DeviceError& e) {
    std::fprintf(stderr, "plume: device error: %s\n", e.what());
    return kExitDeviceFailure;
  } catch (const InternalError& e) {
    std::fprintf(stderr, "plume: internal error: %s\n", e.what());
    return kExitInternal;
  } catch (const std::bad_alloc&) {
    // Host memory, like device memory, is the machine's: another one may have enough.
    std::fprintf(stderr, "plume: device error: out of host memory\n");
    return kExitDeviceFailure;
  } catch (const std::exception& e) {  // not plume's own: a bug or a library's failure, never retried
    std::fprintf(stderr, "plume: internal error: %s\n", e.what());
    return kExitInternal;
  }
}
