// Output handling shared by `plume reference` and `plume render`: frame patterns, up-front
// writability checks, resume (a frame is complete when its EXR reads back with the same
// settings in its header), EXR + optional PNG written atomically (the progress display of a frame
// sequence: core/progress.h).
// Both commands compare a full render key (every setting the pixels depend on) and check up front
// that the VDB file of every frame they are asked for is there (media/volume_frames.h).
#pragma once

#include "app/settings_cli.h"
#include "io/image.h"
#include "scene/render_key.h"
#include "scene/scene.h"
#include "scene/settings.h"

#include <cstdint>
#include <string>
#include <vector>

namespace plume {

struct FrameOutputs {
  std::string pattern;  // -o value; {frame:04} replaced per frame
  bool png = false;
  bool resume = false;

  // Throws InputError if several frames share one path or any output folder is unwritable.
  void check(const RenderSettings& rs) const;
  std::string exrPath(int frame) const;
  std::string pngPath(int frame) const;
  // --resume and the frame's EXR (and PNG with --png) is complete and its header's render_key
  // equals `key`. Otherwise logs why an existing frame is rendered again: other settings (which
  // ones), no key (written by a plume from before render keys), unreadable, or no PNG.
  bool skip(int frame, const RenderKey& key) const;
  // Atomic writes; first removes temporaries of this frame's files left by a killed run (a
  // process that no longer exists on this host, untouched for a minute).
  void write(int frame, const Image& image) const;
};

// What every frame-producing command takes: the scene, -o/--png/--resume, -q, --width/--height
// and every render.* setting as a flag.
struct FrameJobArgs {
  std::string scene;
  FrameOutputs outputs;
  bool quiet = false;
  int width = 0, height = 0;
  SettingOverrides overrides;
};

void addFrameJobOptions(CLI::App& cmd, FrameJobArgs& args);
// The header entries of a frame job's image besides core/image.h's common ones: the scene as
// given, the values the grid's sanitising replaced, and the render key that --resume compares.
void setFrameJobMeta(Image& image, const FrameJobArgs& args, const RenderKey& key, uint64_t replacedValues);
// Loads the scene with the command line's overrides applied; sets the log's quietness.
Scene loadJobScene(const FrameJobArgs& args);

}  // namespace plume
