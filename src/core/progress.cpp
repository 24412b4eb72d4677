#include "core/progress.h"

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

}  // namespace plume
