// plume reference SCENE -o OUT.exr: the independent CPU delta-tracking reference (DESIGN §4.1).
#include "app/commands.h"
#include "app/frame_output.h"
#include "app/settings_cli.h"
#include "core/error.h"
#include "core/log.h"
#include "io/image.h"
#include "media/vdb_loader.h"
#include "reference/reference.h"
#include "scene/scene.h"

#include <memory>

namespace plume {
namespace {

struct ReferenceArgs {
  std::string scene;
  FrameOutputs outputs;
  bool quiet = false;
  int width = 0, height = 0;
  SettingOverrides overrides;
};

int runReference(const ReferenceArgs& a) {
  setQuiet(a.quiet);
  Scene scene = loadScene(a.scene);
  applyOverrides(scene.render, a.overrides);
  if (a.width > 0) scene.camera.width = a.width;
  if (a.height > 0) scene.camera.height = a.height;
  ref::checkReferenceSupports(scene);
  const RenderSettings& rs = scene.render;
  a.outputs.check(rs);
  const Medium& medium = scene.media.at(0);
  for (int frame = rs.frameFirst; frame <= rs.frameLast; ++frame) {
    if (a.outputs.skip(frame, rs)) continue;
    LoadedGrid grid = loadFloatGrid(medium.vdbPath(frame), medium.densityGrid);
    if (grid.replacedValues > 0) {
      logWarn(strf("%s: %llu NaN, infinite or negative values replaced by 0", grid.path.c_str(),
                   (unsigned long long)grid.replacedValues));
    }
    ref::ReferenceOptions opt;
    opt.frame = frame;
    opt.progress = !a.quiet;
    ref::ReferenceStats stats;
    Image image = ref::renderReference(scene, grid.grid, opt, &stats);
    image.meta["scene"] = a.scene;
    image.meta["replaced_values"] = std::to_string(grid.replacedValues);
    a.outputs.write(frame, image);
    logInfo(strf("frame %d: %s  %.2fs  %.0f samples/s", frame, a.outputs.exrPath(frame).c_str(), stats.seconds,
                 stats.samplesPerSecond()));
  }
  return kExitOk;
}

}  // namespace

void addReferenceCommand(CLI::App& app, Action& action) {
  auto args = std::make_shared<ReferenceArgs>();
  CLI::App* cmd = app.add_subcommand("reference", "CPU delta-tracking reference render (mean + variance EXR)");
  cmd->add_option("scene", args->scene, "scene JSON file")->required();
  cmd->add_option("-o,--output", args->outputs.pattern, "output EXR; {frame:04} is replaced by the frame")->required();
  cmd->add_flag("--png", args->outputs.png, "also write a tone-mapped PNG preview beside each EXR");
  cmd->add_flag("--resume", args->outputs.resume, "skip frames whose EXR is already complete");
  cmd->add_flag("-q,--quiet", args->quiet, "no progress bar or log lines");
  cmd->add_option("--width", args->width, "override camera.width")->check(CLI::Range(1, 16384));
  cmd->add_option("--height", args->height, "override camera.height")->check(CLI::Range(1, 16384));
  addSettingOptions(*cmd, args->overrides);
  cmd->callback([&action, args] { action = [args] { return runReference(*args); }; });
}

}  // namespace plume
