// `plume bench` (issue 4, DESIGN §6) end to end on a tiny image: it builds and caches the
// reference next to the scene, runs the path tracer curve and the selected ReSTIR variants for a
// static and a moving camera, and the CPU reference beside them, and writes a table, a CSV and an
// SVG whose numbers are sane (finite positive errors and times, the path tracer's and the CPU
// reference's errors falling with their spp, a finite positive gain for every ReSTIR and
// reference row: a sanity check, the gains themselves are a benchmark). A second run reuses the
// cached reference; an edited scene does not.
#include "io/image.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

using namespace plume;
namespace fs = std::filesystem;

namespace {

std::string readText(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::vector<std::string>> csvRows(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::stringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    std::vector<std::string> cells;
    std::stringstream cs(line);
    std::string cell;
    while (std::getline(cs, cell, ',')) cells.push_back(cell);
    rows.push_back(cells);
  }
  return rows;
}

size_t countRefs(const fs::path& dir) {
  size_t n = 0;
  if (fs::exists(dir))
    for (const auto& e : fs::directory_iterator(dir)) n += e.path().extension() == ".exr";
  return n;
}

// The bundled smoke's scene and first grid in `sceneDir`, where the bench may write its cache.
void copySmokeScene(const fs::path& sceneDir) {
  fs::create_directories(sceneDir);
  fs::copy_file(test::sourcePath("volumes/smoke/smoke.json"), sceneDir / "smoke.json", fs::copy_options::overwrite_existing);
  fs::copy_file(test::sourcePath("volumes/smoke/smoke_0001.vdb"), sceneDir / "smoke_0001.vdb",
                fs::copy_options::overwrite_existing);
}

}  // namespace

TEST(BenchCli, WritesTableCsvAndPlotWithSaneNumbersAndCachesTheReference) {
  const fs::path dir = test::outputDir("bench_cli");
  const fs::path sceneDir = dir / "scene";
  copySmokeScene(sceneDir);
  const std::vector<std::string> args = {"bench", (sceneDir / "smoke.json").string(), "-o", (dir / "out").string(),
                                         "--width", "24", "--height", "24", "--ref-spp", "256", "--warmup", "2",
                                         "--measure", "3", "--pt-spp", "1", "4", "--only", "pairwise M4 k2 r16", "R0",
                                         "--cpu-ref-spp", "1", "16", "--save-images"};
  test::RunResult r = test::runPlume(args);
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const fs::path out = dir / "out";
  for (const char* f : {"smoke_bench.md", "smoke_bench.csv", "smoke_bench.svg", "static_reference.exr"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  EXPECT_NE(readText(out / "smoke_bench.svg").find("<svg"), std::string::npos);
  const auto rows = csvRows(readText(out / "smoke_bench.csv"));
  ASSERT_GE(rows.size(), 2u);
  int restirRows = 0;
  std::map<std::string, std::vector<double>> ptErr, cpuErr;
  for (size_t i = 1; i < rows.size(); ++i) {
    ASSERT_EQ(rows[i].size(), 6u) << "row " << i;
    const std::string& cam = rows[i][0];
    const std::string& method = rows[i][1];
    const double ms = std::stod(rows[i][2]), err = std::stod(rows[i][3]);
    EXPECT_TRUE(cam == "static" || cam == "moving") << cam;
    EXPECT_TRUE(std::isfinite(ms) && ms > 0) << method;
    EXPECT_TRUE(std::isfinite(err) && err > 0 && err < 10) << method << " relMSE " << err;
    if (method.rfind("pt ", 0) == 0) {
      ptErr[cam].push_back(err);
    } else if (method.rfind("reference ", 0) == 0) {
      cpuErr[cam].push_back(err);
      const double gain = std::stod(rows[i][5]);
      EXPECT_TRUE(std::isfinite(gain) && gain > 0) << method;
    } else {
      ++restirRows;
      const double gain = std::stod(rows[i][5]);
      EXPECT_TRUE(std::isfinite(gain) && gain > 0) << method;
    }
  }
  EXPECT_EQ(restirRows, 4);  // two variants, two cameras
  for (const auto& [cam, e] : ptErr) {
    ASSERT_EQ(e.size(), 2u);
    EXPECT_LT(e[1], e[0]) << cam << ": 4 spp must beat 1 spp";
  }
  // The CPU reference is a method row of both cameras; 16 spp against the converged image (another
  // implementation, another seed) must be well below 1 spp's error (1/16 in expectation).
  ASSERT_EQ(cpuErr.size(), 2u);
  for (const auto& [cam, e] : cpuErr) {
    ASSERT_EQ(e.size(), 2u) << cam;
    EXPECT_LT(e[1], 0.5 * e[0]) << cam << ": the CPU reference at 16 spp must beat 1 spp";
  }
  const std::string md = readText(out / "smoke_bench.md");
  EXPECT_NE(md.find("| static | reference 16 spp |"), std::string::npos) << md;
  EXPECT_NE(readText(out / "smoke_bench.svg").find("CPU reference"), std::string::npos);
  const size_t refs = countRefs(sceneDir / "bench_cache");
  EXPECT_GE(refs, 2u);  // static + moving poses

  // Again, with ReSTIR retuned in the scene file: the cached references are reused (they do not
  // depend on ReSTIR's settings). Then a scene edited where the image depends on it gets new ones.
  std::string scene = readText(sceneDir / "smoke.json");
  const size_t radius = scene.find("\"restir_radius\": 2");
  ASSERT_NE(radius, std::string::npos);
  std::ofstream(sceneDir / "smoke.json") << scene.replace(radius, 18, "\"restir_radius\": 3");
  r = test::runPlume(args);
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_EQ(countRefs(sceneDir / "bench_cache"), refs);
  const size_t at = scene.find("\"density_scale\": 16.0");
  ASSERT_NE(at, std::string::npos);
  scene.replace(at, 21, "\"density_scale\": 12.0");
  std::ofstream(sceneDir / "smoke.json") << scene;
  r = test::runPlume(args);
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_EQ(countRefs(sceneDir / "bench_cache"), 2 * refs);
}

// Without --warmup the bench renders as many frames before measuring as the largest history cap c of
// the ReSTIR variants it runs (one iteration per frame adds M to a history capped at c * M: after c
// frames it is full), at least 4; the table's header says how many.
TEST(BenchCli, WarmUpDefaultsToTheFramesTheHistoryNeedsToFill) {
  const fs::path dir = test::outputDir("bench_cli_warmup");
  const fs::path sceneDir = dir / "scene";
  copySmokeScene(sceneDir);
  for (const auto& [cap, warmup] : {std::pair{"9", "Warm-up 9 frames"}, std::pair{"2", "Warm-up 4 frames"}}) {
    test::RunResult r = test::runPlume({"bench", (sceneDir / "smoke.json").string(), "-o", (dir / "out").string(),
                                        "--width", "8", "--height", "8", "--ref-spp", "16", "--measure", "1",
                                        "--pt-spp", "1", "--no-cpu-ref", "--camera", "static", "--only", "R0",
                                        "--restir-history-cap", cap});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const std::string md = readText(dir / "out" / "smoke_bench.md");
    EXPECT_NE(md.find(warmup), std::string::npos) << "c " << cap << ":\n" << md;
  }
}

// --seed: the methods' random numbers (the same seed, the same errors; another, other errors),
// never the cached converged image's; the table's header names it.
TEST(BenchCli, SeedChangesTheMethodsNumbersNotTheReference) {
  const fs::path dir = test::outputDir("bench_cli_seed");
  const fs::path sceneDir = dir / "scene";
  copySmokeScene(sceneDir);
  auto run = [&](const char* seed) {
    test::RunResult r = test::runPlume({"bench", (sceneDir / "smoke.json").string(), "-o", (dir / "out").string(),
                                        "--width", "8", "--height", "8", "--ref-spp", "64", "--warmup", "1",
                                        "--measure", "1", "--pt-spp", "1", "--no-cpu-ref", "--camera", "static",
                                        "--only", "R0", "--seed", seed});
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(readText(dir / "out" / "smoke_bench.md").find(std::string("Seed ") + seed + "."), std::string::npos);
    std::vector<std::string> errors;  // relMSE of each row, as written
    const auto rows = csvRows(readText(dir / "out" / "smoke_bench.csv"));
    for (size_t i = 1; i < rows.size(); ++i) errors.push_back(rows[i].at(3));
    return errors;
  };
  const std::vector<std::string> a = run("5");
  const size_t refs = countRefs(sceneDir / "bench_cache");
  EXPECT_EQ(refs, 1u);
  ASSERT_EQ(a.size(), 2u);  // pt 1 spp, ReSTIR R0
  EXPECT_EQ(run("5"), a);
  const std::vector<std::string> b = run("6");
  ASSERT_EQ(b.size(), 2u);
  EXPECT_NE(b[0], a[0]);
  EXPECT_NE(b[1], a[1]);
  EXPECT_EQ(countRefs(sceneDir / "bench_cache"), refs);  // the converged image was reused
}

TEST(BenchCli, AnUnknownVariantIsABadInput) {
  test::RunResult r = test::runPlume({"bench", test::sourcePath("volumes/smoke/smoke.json"), "-o",
                                      test::outputDir("bench_cli_bad"), "--width", "8", "--height", "8", "--only",
                                      "no such variant"});
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_NE(r.output.find("--only"), std::string::npos) << r.output;
}

// `plume bench --kernels` on a tiny image: a row per method with a marginal cost, the
// device's events and lane occupancy within [1, 8] (lavapipe's subgroups; any device: [1, 128]),
// the reference's events but no lanes, and the markdown file.
TEST(BenchCli, KernelBenchmarkReportsEveryMethod) {
  const fs::path out = test::outputDir("bench_cli_kernels");
  test::RunResult r = test::runPlume({"bench", test::sourcePath("volumes/smoke/smoke.json"), "--kernels", "--frame", "12",
                                      "--width", "16", "--height", "16", "--kernel-spp", "1", "2", "--kernel-rounds", "1",
                                      "--kernel-count-spp", "1", "-o", out.string()});
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const std::string md = readText(out / "smoke_kernels_16x16.md");
  for (const char* method : {"| path tracer |", "| ReSTIR iteration |", "| CPU reference |"}) {
    const size_t at = md.find(method);
    ASSERT_NE(at, std::string::npos) << method << "\n" << md;
    // | method | ms/sample | quartiles | fixed | steps/s | lookups/s | segments/s | steps/px | lookups/px |
    // segments/px | lanes: tracking | transmittance | DDA | lookups |
    std::vector<std::string> cells;
    std::stringstream line(md.substr(at + 1, md.find('\n', at) - at - 1));
    std::string cell;
    while (std::getline(line, cell, '|')) cells.push_back(cell.substr(cell.find_first_not_of(' ')));
    ASSERT_GE(cells.size(), 14u) << method;
    // Timings at 16² on a loaded machine may even come out negative: a number, not a benchmark here.
    EXPECT_TRUE(std::isfinite(std::stod(cells[1]))) << method << ": ms per sample";
    const double steps = std::stod(cells[7]), lookups = std::stod(cells[8]), segments = std::stod(cells[9]);
    EXPECT_GT(steps, 0.0) << method;
    EXPECT_GT(lookups, 0.0) << method;
    EXPECT_LE(lookups, steps) << method;
    EXPECT_LE(steps, lookups + segments + 0.1) << method;  // rounded to 0.1 in the table
    const bool cpu = std::string(method) == "| CPU reference |";
    const double dda = cpu ? 0 : std::stod(cells[12]);
    if (cpu) {
      EXPECT_EQ(cells[12].rfind("—", 0), 0u) << "the reference is scalar: no lanes";
    } else {
      EXPECT_GE(dda, 1.0) << method;
      EXPECT_LE(dda, 8.0) << method;
    }
  }
}
