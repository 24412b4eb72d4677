// The viewer's ImGui panel: timings, animation transport, estimator switches and live
// parameters. Render settings are drawn from the settings table (scene/settings.h), so a key
// added there (e.g. ReSTIR's M, k, radius) gets a widget without an edit here.
#pragma once

#include "render/features.h"
#include "scene/scene.h"

#include <functional>
#include <string>

namespace plume::viewer {

struct ViewState {
  Scene scene;                  // the working copy the renderer reads
  int frame = 1;
  bool playing = false;
  int sppPerFrame = 1;          // samples added per displayed frame
  int maxSamples = 4096;        // progressive accumulation stops here
  float exposure = 0.0f;        // stops
  bool showUi = true;
  bool userCamera = false;      // the orbit camera overrides the scene's camera path
  std::string status;           // last message (screenshot written, renderer failed...)
};

struct ViewStats {
  std::string device, renderer;
  std::function<bool(const std::string&)> usesSetting;  // the renderer's for the working scene (render/estimator.h)
  double fps = 0, frameMs = 0;
  PassTimes passes;             // renderer passes of the last batch, then "display"
  int samples = 0;
  int width = 0, height = 0;
};

// What the user asked for this frame.
struct UiRequests {
  bool restart = false;         // accumulation must restart (camera-independent edit)
  bool rebuildRenderer = false; // mode, lights or settings changed
  bool screenshot = false;
  bool resetCamera = false;
  int step = 0;                 // frames to step (+-1)
};

UiRequests drawUi(ViewState& state, const ViewStats& stats);

}  // namespace plume::viewer
