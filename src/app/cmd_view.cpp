// plume view SCENE: the interactive viewer (src/viewer); --frames N --screenshot out.png runs N
// frames, saves the image (PNG + EXR) and exits, for tests and demos.
#include "app/commands.h"
#include "app/settings_cli.h"
#include "core/error.h"
#include "core/log.h"
#include "render/estimator.h"
#include "viewer/viewer.h"

#include <memory>

namespace plume {
namespace {

struct ViewArgs {
  std::string scene;
  viewer::ViewerOptions options;
  int width = 0, height = 0;
  SettingOverrides overrides;
};

int runView(ViewArgs& a) {
  setQuiet(a.options.quiet);
  Scene scene = loadScene(a.scene);
  applyOverrides(scene.render, a.overrides);
  if (a.width > 0) scene.camera.width = a.width;
  if (a.height > 0) scene.camera.height = a.height;
  if (scene.media.empty()) throw InputError(scene.path + ": media: the viewer needs a medium");
  const RenderSettings& rs = scene.render;
  int& start = a.options.startFrame;
  if (start != 0 && (start < rs.frameFirst || start > rs.frameLast)) {
    throw InputError(strf("command line: --frame: %d is outside render.frames [%d, %d]", start, rs.frameFirst, rs.frameLast));
  }
  if (a.options.scriptedFrames == 0 && !a.options.captureWindow.empty()) {
    throw InputError("command line: --capture-window needs --frames N (scripted mode)");
  }
  a.options.scene = std::move(scene);
  return viewer::runViewer(a.options);
}

}  // namespace

void addViewCommand(CLI::App& app, Action& action) {
  auto args = std::make_shared<ViewArgs>();
  viewer::ViewerOptions& o = args->options;
  CLI::App* cmd = app.add_subcommand("view", "interactive viewer (GLFW + Vulkan swapchain, ImGui panel)");
  cmd->footer(
      "Mouse: drag orbits, right/middle (or shift) drag pans, wheel zooms. Keys: space play/pause, left/right step, "
      "Home first frame, R reset camera, S screenshot (PNG + EXR), H hide the panel, Esc quit.\n"
      "Scripted: --frames N [--screenshot out.png] runs N frames and exits (use xvfb-run without a display).");
  cmd->add_option("scene", args->scene, "scene JSON file")->required();
  // --frames means "run N frames" here, so the animation range is --range (render.frames).
  cmd->add_option("--frames", o.scriptedFrames, "scripted mode: run this many frames, save --screenshot, exit")
      ->check(CLI::Range(1, 1000000));
  cmd->add_option("--screenshot", o.screenshot, "screenshot PNG path (an EXR is written beside it)");
  cmd->add_option("--capture-window", o.captureWindow, "scripted mode: also save the presented window as PNG");
  cmd->add_option("--frame", o.startFrame, "animation frame to start on (default: the first)");
  cmd->add_option_function<std::string>(
      "--range", [args](const std::string& v) { args->overrides["frames"] = v; },
      "animation frames FIRST-LAST (render.frames)");
  cmd->add_flag("--play", o.play, "start playing the animation");
  cmd->add_flag("--hide-ui", o.hideUi, "start with the panel hidden (H toggles it)");
  cmd->add_option("--width", args->width, "override camera.width")->check(CLI::Range(1, 16384));
  cmd->add_option("--height", args->height, "override camera.height")->check(CLI::Range(1, 16384));
  cmd->add_option("--window-scale", o.windowScale, "window pixels per image pixel (default: fit 1280x720)")
      ->check(CLI::Range(1, 16));
  cmd->add_option("--spp-per-frame", o.sppPerFrame, "samples per pixel added per displayed frame")->check(CLI::Range(1, 4096));
  cmd->add_option("--exposure", o.exposure, "display exposure in stops");
  cmd->add_option("--device", o.device, "Vulkan device to use (substring of its name)");
  cmd->add_flag("-q,--quiet", o.quiet, "no log lines");
  for (const SettingDesc& d : renderSettingsTable()) {
    cmd->add_option_function<std::string>(
        cliFlagFor(d.key), [args, key = std::string(d.key)](const std::string& v) { args->overrides[key] = v; },
        std::string(d.help) + " (render." + d.key + ")");
  }
  cmd->callback([&action, args] { action = [args] { return runView(*args); }; });
}

}  // namespace plume
