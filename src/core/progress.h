// Progress displays: a bar over work items (the CPU reference's tiles) on a terminal (stderr is a
// tty), plain log lines every 10% otherwise; and the progress of a frame sequence (plume render).
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace plume {

class ProgressBar {
 public:
  ProgressBar(std::string label, uint64_t total);
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  void advance(uint64_t n = 1);  // thread-safe
  void finish();
  double elapsedSeconds() const;

 private:
  void draw(uint64_t done, bool final);

  std::string label_;
  uint64_t total_;
  std::atomic<uint64_t> done_{0};
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point lastDraw_;
  int lastDecile_ = -1;
  bool tty_;
  bool finished_ = false;
  std::mutex mutex_;
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

}  // namespace plume
