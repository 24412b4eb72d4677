// plume view: a GLFW window with a Vulkan swapchain showing a renderer's progressive image, an
// orbit camera, animation playback and an ImGui panel. Scripted mode (scriptedFrames > 0) runs
// that many frames, writes the screenshot and exits: tests and demos.
#pragma once

#include "scene/scene.h"

#include <string>

namespace plume::viewer {

struct ViewerOptions {
  Scene scene;                  // loaded, overrides applied
  int startFrame = 0;           // 0: the first frame of render.frames
  int scriptedFrames = 0;       // > 0: run this many frames, save `screenshot`, exit
  std::string screenshot;       // PNG path (an EXR is written beside it); also the S key's name
  std::string captureWindow;    // scripted: PNG of the last presented window image
  bool hideUi = false;
  bool play = false;
  int windowScale = 0;          // window = image size * scale; 0: chosen for the screen
  int sppPerFrame = 1;
  float exposure = 0.0f;
  std::string device;
  bool quiet = false;
};

int runViewer(const ViewerOptions& options);  // exit code; throws InputError / DeviceError

}  // namespace plume::viewer
