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

using ReferenceArgs = FrameJobArgs;

int runReference(const ReferenceArgs& a) {
  Scene scene = loadJobScene(a);
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
  addFrameJobOptions(*cmd, *args);
  cmd->callback([&action, args] { action = [args] { return runReference(*args); }; });
}

}  // namespace plume
