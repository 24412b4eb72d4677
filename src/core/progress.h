// Progress bar on a terminal (stderr is a tty), plain log lines every 10% otherwise.
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

}  // namespace plume
