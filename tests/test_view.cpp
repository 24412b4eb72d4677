// `plume view` in scripted mode under xvfb-run on the Vulkan device (lavapipe here): the
// screenshot is the rendered smoke (not black, not uniform), it matches an offscreen `plume
// render` of the same pose, seed and sample count, and the window as presented through the
// swapchain (panel hidden, one window pixel per image pixel) shows exactly the screenshot's
// pixels. Skipped when xvfb-run is not installed.
#include "io/image.h"
#include "support/test_support.h"

#include <gtest/gtest.h>
#include <png.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

using namespace plume;
namespace fs = std::filesystem;

namespace {

const std::string kScene = test::sourcePath("volumes/smoke/smoke.json");

bool haveXvfbRun() { return std::system("command -v xvfb-run >/dev/null 2>&1") == 0; }

std::string quote(const std::string& s) { return "'" + s + "'"; }

// Runs `plume view ARGS` under a virtual X server; returns the exit code, output in `log`.
int runView(const std::vector<std::string>& args, std::string& log) {
  // Validation layers on: a synchronisation or layout error in the swapchain path fails the test.
  std::string cmd = "PLUME_VALIDATION=1 xvfb-run -a -s '-screen 0 1024x768x24' ";
  cmd += quote(PLUME_EXE);
  cmd += " view";
  for (const auto& a : args) cmd.append(" ").append(quote(a));
  cmd += " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return -1;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, pipe)) > 0) log.append(buf, n);
  int status = pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

struct Rgb8 {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;
};

Rgb8 readPng(const std::string& path) {
  Rgb8 out;
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&image, path.c_str())) return out;
  image.format = PNG_FORMAT_RGB;
  out.rgb.resize(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, out.rgb.data(), 0, nullptr)) return {};
  out.width = int(image.width);
  out.height = int(image.height);
  return out;
}

double luminance(const Image& img, size_t i) {
  return 0.2126 * img.rgb[3 * i] + 0.7152 * img.rgb[3 * i + 1] + 0.0722 * img.rgb[3 * i + 2];
}

// The presented window (dir/window.png) equals the screenshot PNG (dir/view.png): the display
// pass tone-maps on the GPU with the PNG writer's curve; one level of rounding allowed.
void expectWindowIsTheScreenshot(const std::string& dir, int width, int height) {
  const Rgb8 window = readPng(dir + "/window.png"), png = readPng(dir + "/view.png");
  ASSERT_EQ(window.width, width) << "window capture missing or sized wrongly";
  ASSERT_EQ(window.height, height);
  ASSERT_EQ(png.rgb.size(), window.rgb.size());
  int worst = 0;
  for (size_t i = 0; i < png.rgb.size(); ++i) worst = std::max(worst, std::abs(int(png.rgb[i]) - int(window.rgb[i])));
  EXPECT_LE(worst, 1);
}

}  // namespace

// Runs the viewer on `scene` for 8 path-traced frames and compares its screenshot with an
// offscreen render of the same samples, and the presented window with the screenshot.
void expectScriptedViewMatchesRender(const std::string& scene, const std::string& name) {
  const std::string dir = test::outputDir(name);
  const std::vector<std::string> pose = {"--width", "64", "--height", "48", "--seed", "3"};
  std::string log;
  std::vector<std::string> args = {scene, "--frames", "8", "--screenshot", dir + "/view.png",
                                   "--capture-window", dir + "/window.png", "--window-scale", "1", "--hide-ui"};
  args.insert(args.end(), pose.begin(), pose.end());
  ASSERT_EQ(runView(args, log), 0) << log;
  EXPECT_EQ(log.find("validation:"), std::string::npos) << log;

  std::vector<std::string> render = {"render", scene, "--frames", "1", "--spp", "8", "-o", dir + "/render.exr", "--png"};
  render.insert(render.end(), pose.begin(), pose.end());
  test::RunResult r = test::runPlume(render);
  ASSERT_EQ(r.exitCode, 0) << r.output;

  const Image view = readExr(dir + "/view.exr"), offscreen = readExr(dir + "/render.exr");
  ASSERT_EQ(view.width, 64);
  ASSERT_EQ(view.height, 48);
  ASSERT_EQ(view.pixelCount(), offscreen.pixelCount());
  EXPECT_EQ(view.meta.at("spp"), "8");
  // Not black, not uniform: the smoke covers part of the frame against a darker sky.
  double mean = 0, lo = 1e30, hi = -1e30;
  for (size_t i = 0; i < view.pixelCount(); ++i) {
    const double l = luminance(view, i);
    mean += l / double(view.pixelCount());
    lo = std::min(lo, l);
    hi = std::max(hi, l);
  }
  EXPECT_GT(mean, 1e-3);
  EXPECT_GT(hi - lo, 0.05) << "a uniform image is not the smoke";
  // Close to the offscreen render: the same samples (seed, frame, sample indices), so only
  // the order of the accumulation may differ.
  double relMse = 0;
  for (size_t i = 0; i < view.rgb.size(); ++i) {
    const double d = double(view.rgb[i]) - double(offscreen.rgb[i]);
    relMse += d * d / (double(offscreen.rgb[i]) * offscreen.rgb[i] + 1e-2) / double(view.rgb.size());
  }
  EXPECT_LT(relMse, 1e-6);

  expectWindowIsTheScreenshot(dir, 64, 48);
}

TEST(View, ScriptedScreenshotIsTheSmokeAndMatchesAnOffscreenRender) {
  if (!haveXvfbRun()) GTEST_SKIP() << "xvfb-run is not installed";
  expectScriptedViewMatchesRender(kScene, "view");
}

// Surfaces with the path tracer (the bundled smoke over a ground beside a conductor sphere).
TEST(View, SurfacesWithThePathTracerMatchAnOffscreenRender) {
  if (!haveXvfbRun()) GTEST_SKIP() << "xvfb-run is not installed";
  expectScriptedViewMatchesRender(test::sourcePath("volumes/smoke/smoke_ground.json"), "view_surfaces");
}

// ReSTIR in the viewer: the display pass reads ReSTIR's device accumulation in place; the
// presented window must equal the screenshot PNG (written from the read-back mean), and the
// image is the scene (not uniform) with the accumulated iteration count.
void expectRestirWindowShowsItsAccumulation(const std::string& scene, const std::string& name, int frames, int width,
                                            int height) {
  const std::string dir = test::outputDir(name);
  std::string log;
  const std::vector<std::string> args = {scene, "--mode", "restir", "--frames", std::to_string(frames),
                                         "--screenshot", dir + "/view.png", "--capture-window", dir + "/window.png",
                                         "--window-scale", "1", "--hide-ui", "--width", std::to_string(width),
                                         "--height", std::to_string(height), "--seed", "3"};
  ASSERT_EQ(runView(args, log), 0) << log;
  EXPECT_EQ(log.find("validation:"), std::string::npos) << log;
  const Image view = readExr(dir + "/view.exr");
  EXPECT_EQ(view.meta.at("spp"), std::to_string(frames));
  double lo = 1e30, hi = -1e30;
  for (size_t i = 0; i < view.pixelCount(); ++i) lo = std::min(lo, luminance(view, i)), hi = std::max(hi, luminance(view, i));
  EXPECT_GT(hi - lo, 0.05) << "a uniform image is not the scene";
  expectWindowIsTheScreenshot(dir, width, height);
}

// ReSTIR with surfaces in the viewer (the bundled smoke over a ground beside a conductor sphere).
TEST(View, SurfacesWithRestirShowTheirAccumulatedImage) {
  if (!haveXvfbRun()) GTEST_SKIP() << "xvfb-run is not installed";
  expectRestirWindowShowsItsAccumulation(test::sourcePath("volumes/smoke/smoke_ground.json"), "view_restir_surfaces", 3,
                                         48, 32);
}

TEST(View, RestirWindowShowsItsAccumulatedImage) {
  if (!haveXvfbRun()) GTEST_SKIP() << "xvfb-run is not installed";
  expectRestirWindowShowsItsAccumulation(kScene, "view_restir", 6, 64, 48);
}

// The display pass tone-maps each image pixel once and writes the window pixels that show it
// (shaders/viewer/display.comp): at three and at four window pixels per image pixel (four: the
// 16-byte row stores of the default window's fit) the presented window is the screenshot enlarged
// by nearest neighbour, every block one image pixel.
TEST(View, EnlargedWindowShowsEachImagePixelAsABlock) {
  if (!haveXvfbRun()) GTEST_SKIP() << "xvfb-run is not installed";
  for (int scale : {3, 4}) {
    const std::string dir = test::outputDir("view_enlarged_" + std::to_string(scale));
    std::string log;
    ASSERT_EQ(runView({kScene, "--frames", "3", "--width", "50", "--height", "30", "--window-scale",
                       std::to_string(scale), "--hide-ui", "--screenshot", dir + "/view.png", "--capture-window",
                       dir + "/window.png"}, log), 0)
        << log;
    const Rgb8 window = readPng(dir + "/window.png"), png = readPng(dir + "/view.png");
    const int ww = 50 * scale, wh = 30 * scale;
    ASSERT_EQ(window.width, ww);
    ASSERT_EQ(window.height, wh);
    ASSERT_EQ(png.width, 50);
    int worst = 0;
    for (int y = 0; y < wh; ++y) {
      for (int x = 0; x < ww; ++x) {
        for (int c = 0; c < 3; ++c) {
          const int w = window.rgb[3 * (size_t(y) * ww + x) + c];
          const int p = png.rgb[3 * (size_t(y / scale) * 50 + x / scale) + c];
          worst = std::max(worst, std::abs(w - p));
        }
      }
    }
    EXPECT_LE(worst, 1) << "the window must be the screenshot, each pixel a block of " << scale << " x " << scale;
  }
}

TEST(View, PanelIsDrawnOverTheImageWhenShown) {
  if (!haveXvfbRun()) GTEST_SKIP() << "xvfb-run is not installed";
  const std::string dir = test::outputDir("view");
  std::string log;
  ASSERT_EQ(runView({kScene, "--frames", "3", "--width", "160", "--height", "90", "--window-scale", "4",
                     "--screenshot", dir + "/view.png", "--capture-window", dir + "/window.png"}, log), 0)
      << log;
  const Rgb8 window = readPng(dir + "/window.png");
  ASSERT_EQ(window.width, 640);
  ASSERT_EQ(window.height, 360);
  // The panel's title bar sits at the top left: (8, 8) onwards is not the sky's colour.
  const Rgb8 png = readPng(dir + "/view.png");
  const unsigned char* sky = &png.rgb[0];
  const unsigned char* panel = &window.rgb[3 * (12 * 640 + 40)];
  EXPECT_GT(std::abs(int(panel[0]) - int(sky[0])) + std::abs(int(panel[1]) - int(sky[1])) +
                std::abs(int(panel[2]) - int(sky[2])), 20);
  EXPECT_NE(log.find("fps"), std::string::npos) << log;
}

// The panel's per-pass times are the passes' own once a render pass has run on the queue: on
// lavapipe a timestamp was taken by llvmpipe's rasterizer at its next flush as soon as a
// framebuffer had been bound (the panel's), so every pass of every frame after the first read
// ~0.03 ms (their sum 0.2% of the frame); gpu/pipeline.cpp GpuTimer::stamp. ReSTIR's passes are
// a large part of a viewer frame even at this small size: 3.4 of 18 ms (19%) in session 27, whose
// faster passes took them below the 20% this test asked until then; 5% is still 25 times the
// broken timestamps' share.
TEST(View, PassTimesWithThePanelShownAreThePassesOwn) {
  if (!haveXvfbRun()) GTEST_SKIP() << "xvfb-run is not installed";
  std::string log;
  ASSERT_EQ(runView({kScene, "--frames", "6", "--width", "96", "--height", "64", "--mode", "restir"}, log), 0) << log;
  const size_t frameAt = log.find(" ms/frame");
  const size_t passesAt = log.find("last frame's passes: ");
  ASSERT_NE(frameAt, std::string::npos) << log;
  ASSERT_NE(passesAt, std::string::npos) << log;
  const double frameMs = std::stod(log.substr(log.rfind(' ', frameAt - 1) + 1));
  // "name ms, name ms, ..." up to the end of the line; the renderer's passes are all but "display".
  const std::string line = log.substr(passesAt + 21, log.find('\n', passesAt) - passesAt - 21);
  double renderer = 0;
  int count = 0;
  for (size_t at = 0; at < line.size();) {
    const size_t end = std::min(line.find(", ", at), line.size());
    const std::string item = line.substr(at, end - at);
    const size_t ms = item.rfind(" ms");
    ASSERT_NE(ms, std::string::npos) << item;
    const size_t value = item.rfind(' ', ms - 1);
    if (item.substr(0, value) != "display") {
      renderer += std::stod(item.substr(value + 1, ms - value - 1));
      ++count;
    }
    at = end + 2;
  }
  EXPECT_GE(count, 3) << line;
  EXPECT_GT(renderer, 0.05 * frameMs) << "the renderer's passes, " << renderer << " ms, in a frame of " << frameMs
                                     << " ms:\n" << log;
}

TEST(View, NoDisplayIsADeviceErrorNotACrash) {
  const std::string dir = test::outputDir("view");
  const std::string cmd = "env -u DISPLAY -u WAYLAND_DISPLAY " + quote(PLUME_EXE) + " view " + quote(kScene) +
                          " --frames 1 --screenshot " + quote(dir + "/x.png") + " >/dev/null 2>&1";
  const int status = std::system(cmd.c_str());
  EXPECT_EQ(WEXITSTATUS(status), 3);
  EXPECT_FALSE(fs::exists(dir + "/x.png"));
}
