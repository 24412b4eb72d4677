// plume reference SCENE -o OUT.exr: the independent CPU delta-tracking reference (DESIGN §4.1).
#include "app/commands.h"
#include "app/frame_output.h"
#include "app/settings_cli.h"
#include "core/error.h"
#include "core/log.h"
#include "io/image.h"
#include "media/vdb_loader.h"
#include "media/volume_frames.h"
#include "reference/reference.h"
#include "scene/scene.h"

#include <memory>
#include <string>

namespace plume {
namespace {

using ReferenceArgs = FrameJobArgs;

// The frame's render key (app/frame_output.h): the scene's part without the settings the reference
// ignores (render.mode, render.density_filter, the ReSTIR ones), and "mode=reference", so that --resume over frames of
// `plume render` renders them again. Per-pixel random streams: no batch or thread count in it.
RenderKey referenceRenderKey(const Scene& scene, int frame) {
  RenderKey key = sceneRenderKey(scene, frame,
                                 [](const std::string& k) {
                                   return k != "mode" && k != "density_filter" && k.rfind("restir_", 0) != 0;
                                 });
  key.add("mode", "reference");
  return key;
}

int runReference(const ReferenceArgs& a) {
  Scene scene = loadJobScene(a);
  ref::checkReferenceSupports(scene);
  const RenderSettings& rs = scene.render;
  a.outputs.check(rs);
  checkVolumeFrames(scene, rs.frameFirst, rs.frameLast);
  // Surfaces are loaded and built once, before the first frame (bad OBJs fail with nothing written).
  std::shared_ptr<const ref::ReferenceSurfaces> surfaces;
  if (!scene.surfaces.empty()) surfaces = std::make_shared<const ref::ReferenceSurfaces>(scene);
  const Medium& medium = scene.medium();
  for (int frame = rs.frameFirst; frame <= rs.frameLast; ++frame) {
    const RenderKey key = referenceRenderKey(scene, frame);
    if (a.outputs.skip(frame, key)) continue;
    LoadedGrid grid = loadFloatGrid(medium.vdbPath(frame), medium.densityGrid);
    if (grid.replacedValues > 0) {
      logWarn(strf("%s: %llu NaN, infinite or negative values replaced by 0", grid.path.c_str(),
                   (unsigned long long)grid.replacedValues));
    }
    grid.clampedValues = clampOpticalDepth(*grid.grid, medium.densityScale);
    if (grid.clampedValues > 0) warnClamped(grid, medium.densityScale);
    ref::ReferenceOptions opt;
    opt.frame = frame;
    opt.surfaces = surfaces;
    opt.progress = !a.quiet;
    ref::ReferenceStats stats;
    Image image = ref::renderReference(scene, grid.grid, opt, &stats);
    setFrameJobMeta(image, a, key, grid.replacedValues);
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
