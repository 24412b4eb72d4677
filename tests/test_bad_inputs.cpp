// The bad-input corpus (tests/bad_inputs/cases.json): every case runs the plume binary on a broken
// scene, VDB file or command line and must fail cleanly: exit code 2 (kExitBadInput), a message
// containing the expected text (the file and the key path), and nothing left in the output
// folder — neither the output file nor a temporary file.
#include "support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

namespace {
namespace fs = std::filesystem;
using nlohmann::json;

struct BadCase {
  std::string name;
  std::vector<std::string> args;    // with {dir} and {out} still in them
  std::vector<std::string> expect;  // substrings of the output
  std::string note;
  std::string skipSanitized;  // why the AddressSanitizer build skips the case (a library's bug), or ""
};

std::string corpusDir() { return plume::test::sourcePath("tests/bad_inputs"); }

std::vector<BadCase> loadCases() {
  std::ifstream in(fs::path(corpusDir()) / "cases.json");
  json doc = json::parse(in, nullptr, /*allow_exceptions=*/false);
  std::vector<BadCase> cases;
  if (doc.is_discarded() || !doc.contains("cases")) return cases;
  for (const json& c : doc["cases"]) {
    BadCase bc;
    bc.name = c.at("name").get<std::string>();
    bc.args = c.at("args").get<std::vector<std::string>>();
    const json& e = c.at("expect");
    bc.expect = e.is_string() ? std::vector<std::string>{e.get<std::string>()} : e.get<std::vector<std::string>>();
    bc.note = c.value("note", "");
    bc.skipSanitized = c.value("skip_sanitized", "");
    cases.push_back(bc);
  }
  return cases;
}

std::string substitute(std::string s, const std::string& key, const std::string& value) {
  for (size_t at = s.find(key); at != std::string::npos; at = s.find(key, at + value.size())) {
    s.replace(at, key.size(), value);
  }
  return s;
}

class BadInput : public testing::TestWithParam<BadCase> {};

TEST_P(BadInput, FailsCleanlyWithExitCode2) {
  const BadCase& c = GetParam();
  SCOPED_TRACE(c.note);
#if defined(__SANITIZE_ADDRESS__)
  if (!c.skipSanitized.empty()) GTEST_SKIP() << c.skipSanitized;
#endif
  const std::string out = plume::test::outputDir("bad_inputs/" + c.name);
  std::vector<std::string> args;
  std::string cmdline = "plume";
  for (const std::string& a : c.args) {
    args.push_back(substitute(substitute(a, "{dir}", corpusDir()), "{out}", out));
    cmdline += " " + args.back();
  }
  plume::test::RunResult r = plume::test::runPlume(args);
  EXPECT_EQ(r.exitCode, 2) << cmdline << "\n" << r.output;
  for (const std::string& e : c.expect) {
    EXPECT_NE(r.output.find(e), std::string::npos) << "expected \"" << e << "\" in the message of\n"
                                                   << cmdline << "\n" << r.output;
  }
  // Nothing may be left behind: no output, no temporary file (hidden files included).
  std::vector<std::string> left;
  for (const auto& entry : fs::recursive_directory_iterator(out)) left.push_back(entry.path().string());
  EXPECT_TRUE(left.empty()) << cmdline << " left " << left.size() << " file(s), e.g. " << (left.empty() ? "" : left[0]);
}

INSTANTIATE_TEST_SUITE_P(Corpus, BadInput, testing::ValuesIn(loadCases()),
                         [](const testing::TestParamInfo<BadCase>& info) { return info.param.name; });

TEST(BadInputCorpus, ManifestIsComplete) {
  std::vector<BadCase> cases = loadCases();
  EXPECT_GE(cases.size(), 15u) << "tests/bad_inputs/cases.json is missing or has too few cases";
  for (const BadCase& c : cases) {
    EXPECT_FALSE(c.args.empty()) << c.name;
    EXPECT_FALSE(c.expect.empty()) << c.name;
    // Every file the case names in {dir} exists, unless the case is about a missing file.
    for (const std::string& a : c.args) {
      if (a.rfind("{dir}/", 0) != 0 || a.find("no_such") != std::string::npos) continue;
      EXPECT_TRUE(fs::exists(substitute(a, "{dir}", corpusDir()))) << c.name << ": " << a;
    }
  }
}

}  // namespace
