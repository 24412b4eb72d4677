#include "app/frame_output.h"

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/log.h"
#include "scene/scene.h"

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <unistd.h>

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

bool FrameOutputs::skip(int frame, const RenderKey& key) const {
  const std::string path = exrPath(frame);
  if (!resume || !std::filesystem::exists(path)) return false;
  std::string why;
  try {
    Image img = readExr(path);
    const auto stored = img.meta.find("render_key");
    if (img.meta["frame"] != std::to_string(frame)) {
      why = "its header is for frame " + img.meta["frame"];
    } else if (stored == img.meta.end()) {
      why = "its header has no render_key (written by a plume from before render keys), so its settings are unknown";
    } else if (stored->second != key.text()) {
      why = "it was rendered with other settings: " + key.differences(stored->second);
    } else if (png && !std::filesystem::exists(pngPath(frame))) {
      why = "its PNG is missing";
    }
  } catch (const InputError& e) {
    why = std::string("it cannot be read (") + e.what() + ")";
  }
  if (why.empty()) {
    logInfo(strf("frame %d: %s is complete, skipped", frame, path.c_str()));
    return true;
  }
  logInfo(strf("frame %d: %s exists but %s; rendering it again", frame, path.c_str(), why.c_str()));
  return false;
}

namespace {

// AtomicFile names its temporary ".<name>.tmp<pid>" beside the target (core/atomic_file.cpp).
void removeStaleTemporaries(const std::string& target) {
  namespace fs = std::filesystem;
  const fs::path p(target);
  const fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
  const std::string prefix = "." + p.filename().string() + ".tmp";
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    const std::string digits = name.substr(prefix.size());
    if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos) continue;
    const pid_t pid = pid_t(std::stol(digits));
    const bool alive = pid == getpid() || ::kill(pid, 0) == 0 || errno == EPERM;
    const auto age = fs::file_time_type::clock::now() - fs::last_write_time(entry.path(), ec);
    if (!alive && !ec && age > std::chrono::minutes(1)) {
      fs::remove(entry.path(), ec);
      if (!ec) logInfo("removed " + entry.path().string() + " (left by an interrupted run)");
    }
  }
}

}  // namespace

void FrameOutputs::write(int frame, const Image& image) const {
  removeStaleTemporaries(exrPath(frame));
  if (png) removeStaleTemporaries(pngPath(frame));
  // The PNG first: the EXR's presence marks the frame complete for --resume.
  if (png) writePng(pngPath(frame), image);
  writeExr(exrPath(frame), image);
}

void addFrameJobOptions(CLI::App& cmd, FrameJobArgs& a) {
  cmd.add_option("scene", a.scene, "scene JSON file")->required();
  cmd.add_option("-o,--output", a.outputs.pattern, "output EXR; {frame:04} is replaced by the frame")->required();
  cmd.add_flag("--png", a.outputs.png, "also write a tone-mapped PNG preview beside each EXR");
  cmd.add_flag("--resume", a.outputs.resume, "skip frames whose EXR is already complete");
  cmd.add_flag("-q,--quiet", a.quiet, "no progress bar or log lines");
  cmd.add_option("--width", a.width, "override camera.width")->check(CLI::Range(1, 16384));
  cmd.add_option("--height", a.height, "override camera.height")->check(CLI::Range(1, 16384));
  addSettingOptions(cmd, a.overrides);
}

void setFrameJobMeta(Image& image, const FrameJobArgs& a, const RenderKey& key, uint64_t replacedValues) {
  image.meta["scene"] = a.scene;
  image.meta["replaced_values"] = std::to_string(replacedValues);
  image.meta["render_key"] = key.text();
}

Scene loadJobScene(const FrameJobArgs& a) {
  setQuiet(a.quiet);
  Scene scene = loadScene(a.scene);
  applyOverrides(scene.render, a.overrides);
  if (a.width > 0) scene.camera.width = a.width;
  if (a.height > 0) scene.camera.height = a.height;
  return scene;
}

}  // namespace plume
