// A failed Z-test's inputs and z-scores as EXR files beside its summary, for tests on failure
// (dir: build/test-output/<test>, see tests/support).
#pragma once

#include "core/image.h"
#include "core/stats.h"

#include <string>

namespace plume {

// Writes <dir>/<name>_a.exr, _b.exr, _z.exr and _summary.txt; returns the folder.
std::string writeFailureImages(const std::string& dir, const std::string& name, const Image& a, const Image& b,
                               const ZTestResult& result);

}  // namespace plume
