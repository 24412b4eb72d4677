// Output handling shared by `plume reference` and `plume render`: frame patterns, up-front
// writability checks, resume (a frame is complete when its EXR reads back with the same
// settings in its header), EXR + optional PNG written atomically; and the progress display of a
// frame sequence (bar with per-frame time and ETA on a terminal, one log line per frame otherwise).
// Both commands compare a full render key (every setting the pixels depend on) and check up front
// that the VDB file of every frame they are asked for is there (media/volume_frames.h).
#pragma once

#include "app/settings_cli.h"
#include "io/image.h"
#include "scene/render_key.h"
#include "scene/scene.h"
#include "scene/settings.h"

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
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

// Progress over the frames a run renders (skipped ones are counted out up front; pre-roll frames,
// rendered but not written, are counted in): on a terminal a bar redrawn as samples complete with
// the last frame's time, the mean and the ETA; otherwise (logs, farm jobs) one plain line per
// finished frame with the same numbers.
class FrameProgress {
 public:
  FrameProgress(int framesToRender, int sppPerFrame, bool enabled);
  void beginFrame(int frame);
  void samplesDone(int n);
  void frameDone(int frame, const std::string& path, double seconds, const std::string& detail);
  void frameWarmed(int frame, double seconds);  // a pre-roll frame
  void finish();

 private:
  void drawBar();
  double etaSeconds() const;
  void endFrame(int frame, const std::string& what, double seconds, const std::string& detail);

  int total_, spp_;
  bool enabled_, tty_;
  int done_ = 0, warmed_ = 0, frame_ = 0, samples_ = 0;
  double sumSeconds_ = 0, lastSeconds_ = 0;
  std::chrono::steady_clock::time_point start_, frameStart_, lastDraw_;
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
// Loads the scene with the command line's overrides applied; sets the log's quietness.
Scene loadJobScene(const FrameJobArgs& args);

}  // namespace plume
