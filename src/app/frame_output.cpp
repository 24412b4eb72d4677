#include "app/frame_output.h"

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/log.h"
#include "scene/scene.h"

#include <filesystem>

namespace plume {

void FrameOutputs::check(const RenderSettings& rs) const {
  if (rs.frameLast > rs.frameFirst && !hasFramePattern(pattern)) {
    throw InputError("-o " + pattern + ": several frames need a {frame:04} pattern in the output path");
  }
  for (int frame = rs.frameFirst; frame <= rs.frameLast; ++frame) {
    checkOutputWritable(exrPath(frame));
    if (png) checkOutputWritable(pngPath(frame));
  }
}

std::string FrameOutputs::exrPath(int frame) const { return expandFramePattern(pattern, frame); }

std::string FrameOutputs::pngPath(int frame) const {
  return std::filesystem::path(exrPath(frame)).replace_extension(".png").string();
}

bool FrameOutputs::skip(int frame, const RenderSettings& rs) const {
  const std::string path = exrPath(frame);
  if (!resume || !std::filesystem::exists(path)) return false;
  try {
    Image img = readExr(path);
    bool same = img.meta["spp"] == std::to_string(rs.spp) && img.meta["seed"] == std::to_string(rs.seed) &&
                img.meta["frame"] == std::to_string(frame);
    if (same && (!png || std::filesystem::exists(pngPath(frame)))) {
      logInfo(strf("frame %d: %s is complete, skipped", frame, path.c_str()));
      return true;
    }
  } catch (const InputError&) {
  }
  return false;
}

void FrameOutputs::write(int frame, const Image& image) const {
  // The PNG first: the EXR's presence marks the frame complete for --resume.
  if (png) writePng(pngPath(frame), image);
  writeExr(exrPath(frame), image);
}

}  // namespace plume
