#include "support/test_support.h"

#include "core/stats.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <sys/wait.h>
#include <unistd.h>

namespace plume::test {
namespace fs = std::filesystem;

std::string sourcePath(const std::string& rel) { return (fs::path(PLUME_SOURCE_DIR) / rel).string(); }

namespace {
fs::path sharedVolumesLocation() {
  return fs::path(PLUME_SOURCE_DIR) / ".." / "shared" / "volumes" / "blender-mantaflow";
}
}  // namespace

std::string sharedVolumesPath() {
  const fs::path p = sharedVolumesLocation();
  return fs::is_directory(p) ? fs::canonical(p).string() : std::string();
}

std::string sharedVolumesMissing() {
  return "the Blender caches are not present: no folder " + sharedVolumesLocation().lexically_normal().string() +
         " (../shared beside the checkout)";
}

std::string outputDir(const std::string& name) {
  // ctest runs tests in parallel processes: each test gets its own folder under `name`.
  fs::path p = fs::path(PLUME_BINARY_DIR) / "test-output" / name;
  if (const auto* info = ::testing::UnitTest::GetInstance()->current_test_info()) {
    p /= std::string(info->test_suite_name()) + "." + info->name();
  } else {
    p /= "process" + std::to_string(getpid());  // suite set-up: one folder per process
  }
  fs::remove_all(p);
  fs::create_directories(p);
  return p.string();
}

namespace {
std::string shellQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}
}  // namespace

RunResult runPlume(const std::vector<std::string>& args) {
  std::string cmd = shellQuote(PLUME_EXE);
  for (const auto& a : args) cmd.append(" ").append(shellQuote(a));
  cmd += " 2>&1";
  RunResult result;
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return result;
  std::array<char, 4096> buf;
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) result.output.append(buf.data(), n);
  int status = pclose(pipe);
  result.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

void expectChi2(const std::vector<double>& observed, const std::vector<double>& expected, const std::string& dirName,
                const std::string& what, int testCount) {
  const Chi2Result r = chi2Test(observed, expected, kChi2SignificanceLevel, testCount);
  if (!r.pass) writeChi2Report(outputDir(dirName), "chi2", r);
  EXPECT_TRUE(r.pass) << what << "\n" << r.table;
}

}  // namespace plume::test
