#include "core/progress.h"

#include "core/log.h"

#include <algorithm>
#include <cstdio>
#include <unistd.h>

namespace plume {

ProgressBar::ProgressBar(std::string label, uint64_t total)
    : label_(std::move(label)), total_(total ? total : 1), start_(std::chrono::steady_clock::now()),
      lastDraw_(start_), tty_(isatty(STDERR_FILENO) != 0) {}

ProgressBar::~ProgressBar() { finish(); }

double ProgressBar::elapsedSeconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void ProgressBar::advance(uint64_t n) {
  uint64_t done = done_.fetch_add(n) + n;
  auto now = std::chrono::steady_clock::now();
  std::unique_lock lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock() || finished_) return;
  if (tty_) {
    if (now - lastDraw_ < std::chrono::milliseconds(100) && done < total_) return;
    lastDraw_ = now;
    draw(done, false);
  } else {
    int decile = int(10 * done / total_);
    if (decile != lastDecile_ && decile < 10) {
      lastDecile_ = decile;
      draw(done, false);
    }
  }
}

void ProgressBar::finish() {
  std::lock_guard lock(mutex_);
  if (finished_) return;
  finished_ = true;
  draw(done_.load(), true);
}

void ProgressBar::draw(uint64_t done, bool final) {
  double frac = double(done) / double(total_);
  if (frac > 1) frac = 1;
  double elapsed = elapsedSeconds();
  double eta = frac > 0 ? elapsed * (1 - frac) / frac : 0;
  if (tty_) {
    const int width = 30;
    int filled = int(frac * width);
    std::string bar(size_t(filled), '#');
    bar.resize(width, '-');
    std::fprintf(stderr, "\r%s [%s] %5.1f%%  %.1fs  eta %.1fs ", label_.c_str(), bar.c_str(),
                 100 * frac, elapsed, eta);
    if (final) std::fprintf(stderr, "\n");
  } else {
    std::fprintf(stderr, "%s: %.0f%% (%.1fs)\n", label_.c_str(), 100 * frac, elapsed);
  }
  std::fflush(stderr);
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

}  // namespace plume
