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

FrameProgress::FrameProgress(int framesToRender, int sppPerFrame, bool enabled)
    : total_(std::max(0, framesToRender)), spp_(std::max(1, sppPerFrame)), enabled_(enabled),
      tty_(isatty(STDERR_FILENO) != 0), start_(std::chrono::steady_clock::now()), frameStart_(start_), lastDraw_(start_) {}

void FrameProgress::beginFrame(int frame) {
  frame_ = frame;
  samples_ = 0;
  frameStart_ = std::chrono::steady_clock::now();
  if (enabled_ && tty_) drawBar();
}

void FrameProgress::samplesDone(int n) {
  samples_ += n;
  const auto now = std::chrono::steady_clock::now();
  if (!enabled_ || !tty_ || now - lastDraw_ < std::chrono::milliseconds(100)) return;
  lastDraw_ = now;
  drawBar();
}

double FrameProgress::etaSeconds() const {
  // Remaining frames at the mean time per finished frame (the current frame's elapsed time
  // stands in before one has finished), minus the current frame's part already done.
  const double inFrame = std::chrono::duration<double>(std::chrono::steady_clock::now() - frameStart_).count();
  const double frac = std::min(1.0, double(samples_) / double(spp_));
  double perFrame = done_ > 0 ? sumSeconds_ / done_ : (frac > 0 ? inFrame / frac : 0.0);
  return std::max(0.0, perFrame * (total_ - done_) - (done_ > 0 ? perFrame * frac : inFrame));
}

void FrameProgress::drawBar() {
  const double frac = total_ > 0 ? std::min(1.0, (done_ + std::min(1.0, double(samples_) / spp_)) / total_) : 1.0;
  const int width = 24;
  std::string bar(size_t(frac * width), '#');
  bar.resize(width, '-');
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  std::string times = done_ > 0 ? strf("last %.2fs/frame, mean %.2fs", lastSeconds_, sumSeconds_ / done_) : "";
  std::fprintf(stderr, "\r\033[Krender [%s] %d/%d frames  frame %d  %s  elapsed %.1fs  eta %.1fs", bar.c_str(), done_,
               total_, frame_, times.c_str(), elapsed, etaSeconds());
  std::fflush(stderr);
}

void FrameProgress::frameDone(int frame, const std::string& path, double seconds, const std::string& detail) {
  endFrame(frame, path, seconds, detail);
}

void FrameProgress::frameWarmed(int frame, double seconds) {
  ++warmed_;
  endFrame(frame, "pre-roll (not written)", seconds, "");
}

void FrameProgress::endFrame(int frame, const std::string& what, double seconds, const std::string& detail) {
  ++done_;
  sumSeconds_ += seconds;
  lastSeconds_ = seconds;
  samples_ = 0;
  frameStart_ = std::chrono::steady_clock::now();
  if (!enabled_) return;
  if (tty_) std::fprintf(stderr, "\r\033[K");  // the log line replaces the bar, which is redrawn below it
  logInfo(strf("frame %d (%d/%d): %s  %.2fs  eta %.1fs%s", frame, done_, total_, what.c_str(), seconds, etaSeconds(),
               detail.empty() ? "" : ("  (" + detail + ")").c_str()));
  if (tty_ && done_ < total_) drawBar();
}

void FrameProgress::finish() {
  if (!enabled_) return;
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (tty_) std::fprintf(stderr, "\r\033[K");
  const int written = done_ - warmed_;
  logInfo(strf("rendered %d frame%s%s in %.1fs%s", written, written == 1 ? "" : "s",
               warmed_ > 0 ? strf(" and %d pre-roll frame%s", warmed_, warmed_ == 1 ? "" : "s").c_str() : "", elapsed,
               done_ > 0 ? strf(" (%.2fs/frame)", sumSeconds_ / done_).c_str() : ""));
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

Scene loadJobScene(const FrameJobArgs& a) {
  setQuiet(a.quiet);
  Scene scene = loadScene(a.scene);
  applyOverrides(scene.render, a.overrides);
  if (a.width > 0) scene.camera.width = a.width;
  if (a.height > 0) scene.camera.height = a.height;
  return scene;
}

}  // namespace plume
