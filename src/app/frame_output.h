// Output handling shared by `plume reference` and `plume render`: frame patterns, up-front
// writability checks, resume (a frame is complete when its EXR reads back with the same
// settings in its header), EXR + optional PNG written atomically.
#pragma once

#include "io/image.h"
#include "scene/settings.h"

#include <string>

namespace plume {

struct FrameOutputs {
  std::string pattern;  // -o value; {frame:04} replaced per frame
  bool png = false;
  bool resume = false;

  // Throws InputError if several frames share one path or any output folder is unwritable.
  void check(const RenderSettings& rs) const;
  std::string exrPath(int frame) const;
  std::string pngPath(int frame) const;
  // --resume and the frame's EXR is complete for these settings (mode, spp, seed).
  bool skip(int frame, const RenderSettings& rs) const;
  void write(int frame, const Image& image) const;
};

}  // namespace plume
