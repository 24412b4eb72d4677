// Two tiers of errors (STYLE.md): InputError for what a user can fix (bad scene key, missing
// file, unwritable output, an input too large for the device's limits; exit code 2, one line that
// names the file and key) and DeviceError for a failing device (exit code 3: no or wrong device,
// driver error, out of device memory; another machine may succeed). InternalError is a fault of
// plume itself or of its installation (a shader file missing or not compiling, a broken
// invariant between stages; exit code 4): deterministic, so retrying elsewhere will not help
// unless that machine has another installation. Invariants within a function use PLUME_CHECK,
// which aborts with a location.
#pragma once

#include <stdexcept>
#include <string>

namespace plume {

enum ExitCode : int {
  kExitOk = 0,
  kExitTestFailed = 1,  // e.g. `plume compare` when the Z-test fails
  kExitBadInput = 2,
  kExitDeviceFailure = 3,
  kExitInternal = 4,
};

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class DeviceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class InternalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

[[noreturn]] void checkFailed(const char* expr, const char* file, int line, const std::string& msg);

}  // namespace plume

#define PLUME_CHECK(cond)                                                  \
  do {                                                                     \
    if (!(cond)) ::plume::checkFailed(#cond, __FILE__, __LINE__, {});      \
  } while (0)
#define PLUME_CHECK_MSG(cond, msg)                                         \
  do {                                                                     \
    if (!(cond)) ::plume::checkFailed(#cond, __FILE__, __LINE__, (msg));   \
  } while (0)
