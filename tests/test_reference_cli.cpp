// `plume reference` end to end on the bundled smoke: a 128² frame at 256 spp completes, its
// variance image agrees with the spread between two independent seeds, the same seed gives the
// same pixels, and the header carries the run's metadata; --resume keeps a frame only when its
// header's render key matches (the settings the reference depends on) and says why it renders one
// again; a VDB frame missing from the range fails before the first frame renders.
#include "core/log.h"
#include "io/image.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

using namespace plume;
namespace fs = std::filesystem;

namespace {

const std::string kScene = test::sourcePath("volumes/smoke/smoke.json");

Image renderSeed(const std::string& dir, int seed) {
  const std::string out = dir + "/seed" + std::to_string(seed) + ".exr";
  test::RunResult r = test::runPlume({"reference", kScene, "-o", out,
                                      "--frames", "12", "--spp", "256", "--seed", std::to_string(seed), "-q"});
  EXPECT_EQ(r.exitCode, 0) << r.output;
  return readExr(out);
}

}  // namespace

TEST(ReferenceCli, VarianceImageMatchesSpreadBetweenSeedsOnBundledSmoke) {
  const std::string dir = test::outputDir("reference_cli");
  Image a = renderSeed(dir, 1);
  Image b = renderSeed(dir, 2);
  ASSERT_EQ(a.width, 128);
  ASSERT_TRUE(a.hasVariance() && b.hasVariance());
  // E[(a - b)^2] = var(a) + var(b) per pixel and channel; compare the sums.
  double spread = 0, predicted = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i) {
    spread += double(a.rgb[i] - b.rgb[i]) * (a.rgb[i] - b.rgb[i]);
    predicted += double(a.var[i]) + b.var[i];
  }
  ASSERT_GT(predicted, 0);
  EXPECT_NEAR(spread / predicted, 1.0, 0.05) << "spread " << spread << " predicted " << predicted;
  EXPECT_NE(a.rgb, b.rgb);
  EXPECT_EQ(a.meta["spp"], "256");
  EXPECT_EQ(a.meta["seed"], "1");
  EXPECT_EQ(a.meta["frame"], "12");
  EXPECT_EQ(a.meta["mode"], "reference");
  EXPECT_EQ(a.meta["tracking_truncated"], "0");
  EXPECT_FALSE(a.meta["wall_time_s"].empty());
  EXPECT_EQ(renderSeed(dir, 1).rgb, a.rgb) << "same seed, same pixels";
}

TEST(ReferenceCli, ResumeRendersAFrameAgainWhenASettingItDependsOnChanged) {
  const std::string dir = test::outputDir("reference_cli_resume");
  const std::string out = dir + "/f.exr";
  struct Step {
    std::vector<std::string> args;
    std::string expected;  // in the log: "is complete, skipped" or the setting that changed
  };
  // Each step resumes over the previous step's frame with the full set of arguments. The bundled
  // scene sets max_bounces 8, spp 4, seed 1 and the default rr_start_bounce 3.
  const std::vector<Step> steps = {
      {{"--width", "16"}, ""},
      {{"--width", "16"}, "is complete, skipped"},
      {{"--width", "16", "--mode", "restir", "--restir-radius", "5"}, "is complete, skipped"},  // ignored
      {{"--width", "16", "--max-bounces", "2"}, "max_bounces 8 -> 2"},
      {{"--width", "16", "--max-bounces", "2", "--rr-start-bounce", "1"}, "rr_start_bounce 3 -> 1"},
      {{"--width", "16", "--max-bounces", "2", "--rr-start-bounce", "1", "--seed", "7"}, "seed 1 -> 7"},
      {{"--width", "16", "--max-bounces", "2", "--rr-start-bounce", "1", "--seed", "7", "--spp", "3"}, "spp 4 -> 3"},
      {{"--width", "12", "--max-bounces", "2", "--rr-start-bounce", "1", "--seed", "7", "--spp", "3"},
       "camera.width 16 -> 12"},
      {{"--width", "12", "--max-bounces", "2", "--rr-start-bounce", "1", "--seed", "7", "--spp", "3"},
       "is complete, skipped"},
  };

  Image previous;
  for (size_t i = 0; i < steps.size(); ++i) {
    std::vector<std::string> args = {"reference", kScene, "-o", out, "--frames", "2", "--height", "16", "--resume"};
    args.insert(args.end(), steps[i].args.begin(), steps[i].args.end());
    const auto before = fs::exists(out) ? fs::last_write_time(out) : fs::file_time_type{};
    test::RunResult r = test::runPlume(args);
    ASSERT_EQ(r.exitCode, 0) << "step " << i << ":\n" << r.output;
    Image now = readExr(out);
    if (!steps[i].expected.empty()) {
      EXPECT_NE(r.output.find(steps[i].expected), std::string::npos) << "step " << i << ":\n" << r.output;
    }
    if (steps[i].expected == "is complete, skipped") {
      EXPECT_EQ(fs::last_write_time(out), before) << "step " << i << ": the frame must not be rewritten";
    } else if (i > 0) {
      EXPECT_NE(r.output.find("exists but it was rendered with other settings"), std::string::npos) << r.output;
      EXPECT_NE(fs::last_write_time(out), before) << "step " << i << ": the frame must be rewritten";
      EXPECT_NE(now.meta["render_key"], previous.meta["render_key"]) << "step " << i;
      EXPECT_TRUE(now.width != previous.width || now.rgb != previous.rgb) << "step " << i << ": same pixels";
    }
    EXPECT_NE(now.meta["render_key"].find("mode=reference"), std::string::npos) << now.meta["render_key"];
    EXPECT_EQ(now.meta["render_key"].find("restir_"), std::string::npos) << now.meta["render_key"];
    previous = now;
  }
  EXPECT_EQ(previous.meta["spp"], "3");
  EXPECT_EQ(previous.meta["seed"], "7");
  EXPECT_EQ(previous.width, 12);
}

TEST(ReferenceCli, ResumeRendersAgainAFrameWithoutARenderKeyOrFromTheGpuRenderer) {
  const std::string dir = test::outputDir("reference_cli_resume_old");
  const std::string out = dir + "/f.exr";
  const std::vector<std::string> args = {"reference", kScene, "-o", out, "--frames", "2", "--width", "16",
                                         "--height", "16", "--spp", "2", "--resume"};
  ASSERT_EQ(test::runPlume(args).exitCode, 0);
  Image old = readExr(out);
  ASSERT_FALSE(old.meta["render_key"].empty());
  old.meta.erase("render_key");  // as written by a plume from before render keys
  writeExr(out, old);
  test::RunResult r = test::runPlume(args);
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("no render_key"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("is complete, skipped"), std::string::npos) << r.output;
  EXPECT_FALSE(readExr(out).meta["render_key"].empty()) << "the frame must have been written again";

  // The same frame from `plume render` (same size, spp and seed) is not a reference frame.
  test::RunResult gpu = test::runPlume({"render", kScene, "-o", out, "--frames", "2", "--width", "16", "--height",
                                        "16", "--spp", "2", "-q"});
  ASSERT_EQ(gpu.exitCode, 0) << gpu.output;
  r = test::runPlume(args);
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("mode pt -> reference"), std::string::npos) << r.output;
  EXPECT_EQ(readExr(out).meta["mode"], "reference");
}

// A hole in an animated VDB sequence fails the job up front, naming the file and the scene key.
TEST(ReferenceCli, AMissingVdbFrameFailsBeforeAnyFrameIsRendered) {
  const std::string dir = test::outputDir("reference_cli_missing_frame");
  fs::copy_file(kScene, dir + "/smoke.json");  // its VDB path is relative: it resolves to the copies
  for (int f : {1, 2, 4}) {
    const std::string name = strf("smoke_%04d.vdb", f);
    fs::copy_file(test::sourcePath("volumes/smoke/" + name), dir + "/" + name);
  }
  const std::string out = dir + "/out";
  fs::create_directories(out);
  auto run = [&](const std::string& frames) {
    return test::runPlume({"reference", dir + "/smoke.json", "-o", out + "/f_{frame:04}.exr", "--frames", frames,
                           "--width", "16", "--height", "16", "--spp", "1"});
  };
  test::RunResult r = run("1-4");
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_NE(r.output.find(dir + "/smoke.json: media[0].vdb: frame 3: file not found: "), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("smoke_0003.vdb"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::is_empty(out)) << "no frame may be rendered";
  r = run("1-2");
  EXPECT_EQ(r.exitCode, 0) << "the frames that are there render:\n" << r.output;
}
