// Helpers shared by the test executables: paths, running the plume binary, temp folders.
#pragma once

#include <string>
#include <vector>

namespace plume::test {

std::string sourcePath(const std::string& rel);  // PLUME_SOURCE_DIR / rel
std::string sharedVolumesPath();                 // ../shared/volumes/blender-mantaflow, or "" if absent
// Why a test that needs the Blender caches is skipped (the folder looked for): for GTEST_SKIP().
std::string sharedVolumesMissing();
// A fresh folder build/test-output/<name>/<Suite.Test>/ (emptied first); failing tests write files here.
std::string outputDir(const std::string& name);

struct RunResult {
  int exitCode = -1;
  std::string output;  // stdout and stderr together
};
// Runs `plume` with the arguments (shell-quoted for you).
RunResult runPlume(const std::vector<std::string>& args);

// Chi-square test of observed against expected counts at the suite's level, Šidák-corrected for
// `testCount` tests; on failure the report goes to outputDir(dirName) and the message names
// `what`.
void expectChi2(const std::vector<double>& observed, const std::vector<double>& expected, const std::string& dirName,
                const std::string& what, int testCount = 1);

}  // namespace plume::test
