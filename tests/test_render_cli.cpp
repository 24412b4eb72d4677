// `plume render` as users and farms run it (issue 5, DESIGN §8, docs/farm.md): killed with
// SIGKILL mid-run and rerun with --resume, no frame on disk is ever partial and the result equals
// an uninterrupted run; --resume keeps a frame only when its header's render key matches (mode,
// size, settings, scene) and says why it renders one again; same seed and device give the same
// pixels; ReSTIR frames depend on where their history starts and nothing else; both estimators
// show the same progress and write the full header; a device that does not exist exits 3 naming
// the devices there are, while missing or broken shaders exit 4 (the same on every machine); a
// VDB frame missing from the range fails before the first frame renders; --preroll is accepted
// (a no-op for the path tracer).
#include "core/log.h"
#include "gpu/context.h"
#include "io/image.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <spawn.h>
#include <sys/wait.h>
#include <thread>

using namespace plume;
namespace fs = std::filesystem;

extern char** environ;

namespace {

const std::string kScene = test::sourcePath("volumes/smoke/smoke.json");

std::string framePath(const std::string& dir, int frame) { return dir + "/f_" + strf("%04d", frame) + ".exr"; }

// Small but not instant frames, so that a kill lands mid-sequence (~0.3 s each on lavapipe).
std::vector<std::string> renderArgs(const std::string& dir, const std::string& frames) {
  return {"render", kScene, "-o", dir + "/f_{frame:04}.exr", "--frames", frames, "--width", "80", "--height", "80",
          "--spp", "48", "--batch", "4", "--seed", "11", "-q"};
}

// Tiny frames for the tests that only look at which frames are rendered and at headers.
std::vector<std::string> tinyArgs(const std::string& scene, const std::string& out, const std::string& frames,
                                  const std::vector<std::string>& extra) {
  std::vector<std::string> a = {"render", scene, "-o", out, "--frames", frames, "--height", "16", "--spp", "2"};
  a.insert(a.end(), extra.begin(), extra.end());
  return a;
}

// A copy of the bundled smoke scene in `dir` with another density scale (the VDB path made
// absolute so it still resolves).
std::string smokeSceneWithDensity(const std::string& dir, const std::string& name, const std::string& densityScale) {
  std::ifstream in(kScene);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto replace = [&](const std::string& from, const std::string& to) {
    const size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
  };
  replace("\"smoke_{frame:04}.vdb\"", "\"" + test::sourcePath("volumes/smoke/smoke_{frame:04}.vdb") + "\"");
  replace("\"density_scale\": 16.0", "\"density_scale\": " + densityScale);
  const std::string path = dir + "/" + name;
  std::ofstream(path) << text;
  return path;
}

// A copy of the bundled smoke scene in `dir` with only the listed frames of its VDB sequence beside
// it (the scene's relative VDB path resolves to the copies).
std::string smokeSceneWithFrames(const std::string& dir, const std::vector<int>& frames) {
  fs::copy_file(kScene, dir + "/smoke.json");
  for (int f : frames) {
    const std::string name = strf("smoke_%04d.vdb", f);
    fs::copy_file(test::sourcePath("volumes/smoke/" + name), dir + "/" + name);
  }
  return dir + "/smoke.json";
}

// Sets an environment variable for the plume processes a test starts; restores it after.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (old_) {
      setenv(name_, old_->c_str(), 1);
    } else {
      unsetenv(name_);
    }
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

}  // namespace

TEST(RenderCli, KilledMidRunThenResumeCompletesAndMatchesAnUninterruptedRun) {
  const std::string dir = test::outputDir("render_cli");
  const std::string killedDir = dir + "/killed", refDir = dir + "/reference";
  fs::create_directories(killedDir);
  fs::create_directories(refDir);
  const int first = 1, last = 6;

  // Start the run as a child process and SIGKILL it once the first frame is on disk.
  std::vector<std::string> args = renderArgs(killedDir, "1-6");
  args.insert(args.begin(), PLUME_EXE);
  std::vector<char*> argv;
  for (auto& s : args) argv.push_back(s.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  ASSERT_EQ(posix_spawn(&pid, PLUME_EXE, &actions, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&actions);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!fs::exists(framePath(killedDir, first)) && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ::kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the render finished before it could be killed; make its frames slower";

  // Every file with a frame's name is complete; the rest are hidden temporaries.
  int complete = 0;
  for (int f = first; f <= last; ++f) {
    if (!fs::exists(framePath(killedDir, f))) continue;
    Image img = readExr(framePath(killedDir, f));  // throws on a partial file
    EXPECT_EQ(img.meta["frame"], std::to_string(f));
    ++complete;
  }
  EXPECT_GE(complete, 1);
  EXPECT_LT(complete, last - first + 1) << "killed mid-run, some frames must be missing";
  for (const auto& e : fs::directory_iterator(killedDir)) {
    const std::string name = e.path().filename().string();
    const bool finalName = name.size() == 10 && name.rfind("f_", 0) == 0 && e.path().extension() == ".exr";
    EXPECT_TRUE(finalName || (name[0] == '.' && name.find(".tmp") != std::string::npos)) << name;
  }

  test::RunResult resumed = test::runPlume([&] {
    auto a = renderArgs(killedDir, "1-6");
    a.back() = "--resume";  // not quiet: the skipped frames are logged
    return a;
  }());
  ASSERT_EQ(resumed.exitCode, 0) << resumed.output;
  EXPECT_NE(resumed.output.find("is complete, skipped"), std::string::npos) << resumed.output;

  test::RunResult reference = test::runPlume(renderArgs(refDir, "1-6"));
  ASSERT_EQ(reference.exitCode, 0) << reference.output;
  for (int f = first; f <= last; ++f) {
    Image a = readExr(framePath(killedDir, f)), b = readExr(framePath(refDir, f));
    EXPECT_EQ(a.rgb, b.rgb) << "frame " << f << ": same seed and device must give the same pixels";
  }
}

TEST(RenderCli, SameSeedSamePixelsAndMetadata) {
  const std::string dir = test::outputDir("render_cli");
  auto run = [&](const std::string& name, const std::string& seed) {
    test::RunResult r = test::runPlume({"render", kScene, "-o", dir + "/" + name + ".exr", "--frames", "3", "--width",
                                        "48", "--height", "40", "--spp", "8", "--seed", seed, "-q"});
    EXPECT_EQ(r.exitCode, 0) << r.output;
    return readExr(dir + "/" + name + ".exr");
  };
  Image a = run("a", "5"), b = run("b", "5"), c = run("c", "6");
  EXPECT_EQ(a.rgb, b.rgb);
  EXPECT_EQ(a.var, b.var);
  EXPECT_NE(a.rgb, c.rgb) << "a different seed must change the noise";
  for (const char* key : {"mode", "spp", "seed", "frame", "wall_time_s", "device", "version"}) {
    EXPECT_FALSE(a.meta[key].empty()) << key;
  }
  EXPECT_EQ(a.meta["mode"], "pt");
  EXPECT_EQ(a.meta["spp"], "8");
  EXPECT_EQ(a.meta["seed"], "5");
  EXPECT_EQ(a.meta["frame"], "3");
}

TEST(RenderCli, UnknownDeviceExitsThreeNamingTheDevices) {
  const std::string dir = test::outputDir("render_cli");
  test::RunResult r = test::runPlume({"render", kScene, "-o", dir + "/x.exr", "--frames", "1", "--device", "no-such-device"});
  EXPECT_EQ(r.exitCode, 3) << r.output;
  EXPECT_NE(r.output.find("no-such-device"), std::string::npos) << r.output;
  for (const std::string& name : gpu::Context::listDevices()) {
    EXPECT_NE(r.output.find(name), std::string::npos) << "the message should list " << name << ":\n" << r.output;
  }
  EXPECT_FALSE(fs::exists(dir + "/x.exr"));
}

// Exit code 3 says "retry elsewhere"; a missing or broken shader fails the same way everywhere.
TEST(RenderCli, MissingShadersExitFourNotThree) {
  const std::string dir = test::outputDir("render_cli_shaders");
  fs::create_directories(dir + "/empty");
  {
    ScopedEnv env("PLUME_SHADER_DIR", dir + "/empty");
    test::RunResult r = test::runPlume(tinyArgs(kScene, dir + "/x.exr", "1", {"--width", "16"}));
    EXPECT_EQ(r.exitCode, 4) << r.output;
    EXPECT_NE(r.output.find("shader not found: " + dir + "/empty/"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("PLUME_SHADER_DIR"), std::string::npos) << r.output;
  }
  // A copy of the shaders whose compute entry points do not compile.
  fs::copy(test::sourcePath("shaders"), dir + "/broken", fs::copy_options::recursive);
  for (const auto& e : fs::recursive_directory_iterator(dir + "/broken")) {
    if (e.path().extension() == ".comp") std::ofstream(e.path()) << "#version 450\nvoid main() { not glsl }\n";
  }
  ScopedEnv env("PLUME_SHADER_DIR", dir + "/broken");
  test::RunResult r = test::runPlume(tinyArgs(kScene, dir + "/x.exr", "1", {"--width", "16"}));
  EXPECT_EQ(r.exitCode, 4) << r.output;
  EXPECT_NE(r.output.find("failed to compile"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir + "/x.exr"));
}

// A hole in an animated VDB sequence fails the job up front, naming the file and the scene key,
// not when the frame is reached hours later.
TEST(RenderCli, AMissingVdbFrameFailsBeforeAnyFrameIsRendered) {
  const std::string dir = test::outputDir("render_cli_missing_frame");
  const std::string scene = smokeSceneWithFrames(dir, {1, 2, 4});
  const std::string out = dir + "/out";
  fs::create_directories(out);
  auto expectFails = [&](const std::string& frames, const std::vector<std::string>& extra,
                         const std::vector<std::string>& expected) {
    std::vector<std::string> args = {"--width", "16"};
    args.insert(args.end(), extra.begin(), extra.end());
    test::RunResult r = test::runPlume(tinyArgs(scene, out + "/f_{frame:04}.exr", frames, args));
    EXPECT_EQ(r.exitCode, 2) << r.output;
    for (const std::string& e : expected) EXPECT_NE(r.output.find(e), std::string::npos) << e << " in\n" << r.output;
    EXPECT_TRUE(fs::is_empty(out)) << "no frame may be rendered";
  };
  expectFails("1-5", {}, {scene + ": media[0].vdb: frame 3: file not found: ", "smoke_0003.vdb",
                          "(2 of frames 1-5 cannot be read)"});
  expectFails("1-5", {"--resume"}, {"media[0].vdb: frame 3: file not found"});
  expectFails("4", {"--mode", "restir", "--preroll", "2"}, {"media[0].vdb: frame 3: file not found"});  // pre-roll
  fs::create_directory(dir + "/smoke_0003.vdb");
  expectFails("3", {}, {"media[0].vdb: frame 3: not a regular file: ", "smoke_0003.vdb"});
  test::RunResult r = test::runPlume(tinyArgs(scene, out + "/f_{frame:04}.exr", "1-2", {"--width", "16"}));
  EXPECT_EQ(r.exitCode, 0) << "the frames that are there render:\n" << r.output;
}

TEST(RenderCli, PrerollIsAcceptedAndANoOpForThePathTracer) {
  const std::string dir = test::outputDir("render_cli");
  std::vector<std::string> base = {"render", kScene, "--frames", "4", "--width", "32", "--height", "24", "--spp", "4"};
  auto with = [&](std::vector<std::string> extra, const std::string& out) {
    std::vector<std::string> a = base;
    a.insert(a.end(), {"-o", dir + "/" + out});
    a.insert(a.end(), extra.begin(), extra.end());
    return test::runPlume(a);
  };
  test::RunResult p = with({"--preroll", "3"}, "p.exr"), q = with({}, "q.exr");
  ASSERT_EQ(p.exitCode, 0) << p.output;
  ASSERT_EQ(q.exitCode, 0) << q.output;
  EXPECT_NE(p.output.find("no effect with mode pt"), std::string::npos) << p.output;
  EXPECT_EQ(readExr(dir + "/p.exr").rgb, readExr(dir + "/q.exr").rgb);
  EXPECT_EQ(with({"--preroll", "-1"}, "r.exr").exitCode, 2);
}

TEST(RenderCli, RestirPrerollWarmsWithoutWritingAndIsDeterministic) {
  const std::string dir = test::outputDir("render_cli_restir");
  auto run = [&](const std::string& sub, const std::string& preroll) {
    std::filesystem::create_directories(dir + "/" + sub);
    test::RunResult r = test::runPlume({"render", kScene, "--mode", "restir", "-o", dir + "/" + sub + "/f_{frame:04}.exr",
                                        "--frames", "5-6", "--width", "32", "--height", "32", "--spp", "2",
                                        "--preroll", preroll});
    EXPECT_EQ(r.exitCode, 0) << r.output;
    return r.output;
  };
  const std::string out = run("a", "2");
  EXPECT_NE(out.find("frame 3 (1/4): pre-roll (not written)"), std::string::npos) << out;
  EXPECT_NE(out.find("frame 4 (2/4): pre-roll (not written)"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(framePath(dir + "/a", 3)));
  EXPECT_FALSE(std::filesystem::exists(framePath(dir + "/a", 4)));
  run("b", "2");
  run("c", "0");
  Image a = readExr(framePath(dir + "/a", 6)), b = readExr(framePath(dir + "/b", 6)), c = readExr(framePath(dir + "/c", 6));
  EXPECT_EQ(a.meta["mode"], "restir");
  EXPECT_EQ(a.rgb, b.rgb) << "same seed, same pre-roll: same pixels";
  EXPECT_NE(a.rgb, c.rgb) << "the pre-roll must change the history the frame starts from";
}

TEST(RenderCli, ResumeRendersAFrameAgainWhenASettingItDependsOnChanged) {
  const std::string dir = test::outputDir("render_cli_resume");
  const std::string dense = smokeSceneWithDensity(dir, "dense.json", "16.0");
  const std::string thin = smokeSceneWithDensity(dir, "thin.json", "12.0");
  const std::string out = dir + "/f.exr";
  struct Step {
    std::string scene;
    std::vector<std::string> args;
    std::string expected;  // in the log: "is complete, skipped" or the setting that changed
    bool newPixels = true;  // when rendered again (--batch changes the last bits at most)
  };
  // Each step resumes over the previous step's frame and changes one thing (the arguments are the
  // full set each time). The bundled scene sets restir_radius 2 and max_bounces 8.
  const std::vector<Step> steps = {
      {dense, {"--width", "16"}, ""},
      {dense, {"--width", "16"}, "is complete, skipped"},
      {dense, {"--width", "16", "--restir-radius", "5"}, "is complete, skipped"},  // not the path tracer's
      {dense, {"--width", "16", "--mode", "restir"}, "mode pt -> restir"},
      {dense, {"--width", "16", "--mode", "restir", "--restir-radius", "5"}, "restir_radius 2 -> 5"},
      {dense, {"--width", "16", "--mode", "restir", "--restir-radius", "5", "--max-bounces", "2"},
       "max_bounces 8 -> 2"},
      // the shift changes nothing in a scene without surfaces
      {dense, {"--width", "16", "--mode", "restir", "--restir-radius", "5", "--max-bounces", "2", "--restir-shift", "copy"},
       "is complete, skipped"},
      {dense, {"--width", "16", "--max-bounces", "2"}, "mode restir -> pt"},
      {dense, {"--width", "12", "--max-bounces", "2"}, "camera.width 16 -> 12"},
      {thin, {"--width", "12", "--max-bounces", "2"}, "media[0].density_scale 16 -> 12"},
      {thin, {"--width", "12", "--max-bounces", "2", "--texels", "float32"}, "texels float16 -> float32"},
      {thin, {"--width", "12", "--max-bounces", "2", "--texels", "float32", "--batch", "1"}, "batch 4 -> 1", false},
  };
  Image previous;
  for (size_t i = 0; i < steps.size(); ++i) {
    const Step& step = steps[i];
    std::vector<std::string> args = tinyArgs(step.scene, out, "2", step.args);
    args.push_back("--resume");
    const auto before = fs::exists(out) ? fs::last_write_time(out) : fs::file_time_type{};
    test::RunResult r = test::runPlume(args);
    ASSERT_EQ(r.exitCode, 0) << "step " << i << ":\n" << r.output;
    Image now = readExr(out);
    const bool kept = step.expected == "is complete, skipped";
    if (!step.expected.empty()) {
      EXPECT_NE(r.output.find(step.expected), std::string::npos) << "step " << i << ":\n" << r.output;
    }
    if (kept) {
      EXPECT_EQ(fs::last_write_time(out), before) << "step " << i << ": the frame must not be rewritten";
      EXPECT_EQ(now.meta["render_key"], previous.meta["render_key"]) << "step " << i;
    } else if (i > 0) {
      EXPECT_NE(r.output.find("exists but it was rendered with other settings"), std::string::npos) << r.output;
      EXPECT_NE(fs::last_write_time(out), before) << "step " << i << ": the frame must be rewritten";
      EXPECT_NE(now.meta["render_key"], previous.meta["render_key"]) << "step " << i;
      if (step.newPixels) {
        EXPECT_TRUE(now.width != previous.width || now.rgb != previous.rgb) << "step " << i << ": same pixels";
      }
    }
    EXPECT_NE(now.meta["render_key"].find("texels="), std::string::npos) << now.meta["render_key"];
    previous = now;
  }
  EXPECT_EQ(previous.meta["mode"], "pt");
  EXPECT_EQ(previous.meta["max_bounces"], "2");
  EXPECT_EQ(previous.meta["texels"], "float32");
  EXPECT_EQ(previous.meta["batch"], "1");
  EXPECT_EQ(previous.width, 12);
}

TEST(RenderCli, ResumeRendersAgainAFrameWrittenWithoutARenderKey) {
  const std::string dir = test::outputDir("render_cli_resume_old");
  const std::string out = dir + "/f.exr";
  auto args = tinyArgs(kScene, out, "2", {"--width", "16"});
  ASSERT_EQ(test::runPlume(args).exitCode, 0);
  Image old = readExr(out);
  ASSERT_FALSE(old.meta["render_key"].empty());
  old.meta.erase("render_key");  // as written by a plume from before render keys
  writeExr(out, old);
  args.push_back("--resume");
  test::RunResult r = test::runPlume(args);
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("no render_key"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("is complete, skipped"), std::string::npos) << r.output;
  EXPECT_FALSE(readExr(out).meta["render_key"].empty()) << "the frame must have been written again";
}

TEST(RenderCli, RestirShowsTheSameProgressAndHeaderAsThePathTracer) {
  const std::string dir = test::outputDir("render_cli_progress");
  auto run = [&](const std::string& mode) {
    test::RunResult r = test::runPlume(tinyArgs(kScene, dir + "/" + mode + "_{frame:04}.exr", "5-6",
                                                {"--width", "16", "--mode", mode, "--preroll", "1"}));
    EXPECT_EQ(r.exitCode, 0) << r.output;
    return r.output;
  };
  const std::string pt = run("pt"), restir = run("restir");
  EXPECT_NE(pt.find("frame 5 (1/2): " + dir + "/pt_0005.exr"), std::string::npos) << pt;
  EXPECT_NE(pt.find("frame 6 (2/2): " + dir + "/pt_0006.exr"), std::string::npos) << pt;
  EXPECT_NE(pt.find("rendered 2 frames in"), std::string::npos) << pt;
  EXPECT_NE(restir.find("frame 4 (1/3): pre-roll (not written)"), std::string::npos) << restir;
  EXPECT_NE(restir.find("frame 5 (2/3): " + dir + "/restir_0005.exr"), std::string::npos) << restir;
  EXPECT_NE(restir.find("frame 6 (3/3): " + dir + "/restir_0006.exr"), std::string::npos) << restir;
  EXPECT_NE(restir.find("rendered 2 frames and 1 pre-roll frame in"), std::string::npos) << restir;
  for (const std::string& out : {pt, restir}) {
    const size_t line = out.find("frame 6 (");
    ASSERT_NE(line, std::string::npos) << out;
    EXPECT_NE(out.substr(line, out.find('\n', line) - line).find("eta"), std::string::npos) << out;
  }

  const std::vector<const char*> common = {"version", "mode", "spp", "seed", "frame", "max_bounces", "device",
                                           "texels", "wall_time_s", "tracking_truncated", "replaced_values",
                                           "scene", "render_key", "variant"};
  Image p = readExr(dir + "/pt_0006.exr"), r = readExr(dir + "/restir_0006.exr");
  for (const char* key : common) {
    EXPECT_FALSE(p.meta[key].empty()) << "pt: " << key;
    EXPECT_FALSE(r.meta[key].empty()) << "restir: " << key;
  }
  for (const char* key : {"batch", "pass_times_last_batch"}) EXPECT_FALSE(p.meta[key].empty()) << key;
  for (const char* key : {"restir", "restir_iterations_averaged", "restir_history_from", "pass_times_last_iteration",
                          "dropped_non_finite_reservoirs"}) {
    EXPECT_FALSE(r.meta[key].empty()) << key;
  }
  EXPECT_EQ(r.meta["mode"], "restir");
  EXPECT_EQ(r.meta["max_bounces"], "8");
  EXPECT_EQ(r.meta["restir_history_from"], "4");
  EXPECT_EQ(r.meta["restir_iterations_averaged"], "2");  // spp 2: none settles
  EXPECT_EQ(r.meta["dropped_non_finite_reservoirs"], "0");
  EXPECT_EQ(r.meta["restir"], "restir pairwise M4 k2 r2 R1 c20");
}

// docs/farm.md: a ReSTIR frame is determined by the frame its history starts from (the chunk's
// first frame less the pre-roll, or a gap left by --resume), not by how the range is split; with
// restir_history_cap 0 frames are independent, as with pt.
TEST(RenderCli, RestirFramesDependOnlyOnWhereTheirHistoryStarts) {
  const std::string dir = test::outputDir("render_cli_restir_chunks");
  auto run = [&](const std::string& sub, const std::string& frames, std::vector<std::string> extra) {
    extra.insert(extra.end(), {"--width", "16", "--mode", "restir", "-q"});
    test::RunResult r = test::runPlume(tinyArgs(kScene, dir + "/" + sub + "/f_{frame:04}.exr", frames, extra));
    EXPECT_EQ(r.exitCode, 0) << r.output;
    return readExr(framePath(dir + "/" + sub, 3));
  };
  for (const char* sub : {"long", "chunk", "cold", "long0", "chunk0"}) fs::create_directories(dir + "/" + sub);
  Image whole = run("long", "1-3", {}), chunk = run("chunk", "3", {"--preroll", "2"}), cold = run("cold", "3", {});
  EXPECT_EQ(whole.meta["restir_history_from"], "1");
  EXPECT_EQ(chunk.meta["restir_history_from"], "1");
  EXPECT_EQ(cold.meta["restir_history_from"], "3");
  EXPECT_EQ(whole.rgb, chunk.rgb) << "a pre-roll back to the run's first frame reproduces the long run";
  EXPECT_NE(whole.rgb, cold.rgb) << "a chunk starting cold has another history";
  Image whole0 = run("long0", "1-3", {"--restir-history-cap", "0"});
  Image chunk0 = run("chunk0", "3", {"--restir-history-cap", "0"});
  EXPECT_EQ(chunk0.meta["restir_history_from"], "3");
  EXPECT_EQ(whole0.rgb, chunk0.rgb) << "without temporal reuse ReSTIR frames are independent";
}
