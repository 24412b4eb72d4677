#include "core/log.h"

#include "core/error.h"

#include <cstdarg>
#include <cstdio>
#include <cstdlib>

namespace plume {
namespace {
bool gQuiet = false;
}

std::string strf(const char* fmt, ...) {
  va_list args;
  va_start(args, fmt);
  va_list copy;
  va_copy(copy, args);
  int n = std::vsnprintf(nullptr, 0, fmt, copy);
  va_end(copy);
  std::string out(n > 0 ? size_t(n) : 0, '\0');
  if (n > 0) std::vsnprintf(out.data(), out.size() + 1, fmt, args);
  va_end(args);
  return out;
}

void logInfo(const std::string& msg) {
  if (!gQuiet) std::fprintf(stderr, "plume: %s\n", msg.c_str());
}

void logWarn(const std::string& msg) { std::fprintf(stderr, "plume: warning: %s\n", msg.c_str()); }

void setQuiet(bool quiet) { gQuiet = quiet; }

void checkFailed(const char* expr, const char* file, int line, const std::string& msg) {
  std::fprintf(stderr, "plume: internal error: check `%s` failed at %s:%d%s%s\n", expr, file, line,
               msg.empty() ? "" : ": ", msg.c_str());
  std::abort();
}

}  // namespace plume
