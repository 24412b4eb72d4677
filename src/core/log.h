// Minimal logging and printf-style formatting (GCC 12 has no std::format).
#pragma once

#include <string>

namespace plume {

std::string strf(const char* fmt, ...) __attribute__((format(printf, 1, 2)));

void logInfo(const std::string& msg);   // stderr, "plume: ..."
void logWarn(const std::string& msg);   // stderr, "plume: warning: ..."
void setQuiet(bool quiet);              // silences logInfo (warnings still print)

}  // namespace plume
