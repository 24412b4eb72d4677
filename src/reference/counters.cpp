#include "reference/counters.h"

#include <algorithm>
#include <atomic>
#include <mutex>
#include <vector>

namespace plume::ref {
namespace {

std::atomic<bool> gCounting{false};
std::mutex gMutex;
std::vector<KernelCounts*> gThreads;  // every live thread's totals
KernelCounts gRetired;                // totals of threads that have ended

void add(WalkCounts& to, const WalkCounts& c) {
  to.walks += c.walks;
  to.segments += c.segments;
  to.steps += c.steps;
  to.lookups += c.lookups;
}

void add(KernelCounts& to, const KernelCounts& c) {
  add(to.collision, c.collision);
  add(to.transmittance, c.transmittance);
}

struct ThreadCounts {
  KernelCounts counts;
  ThreadCounts() {
    std::lock_guard lock(gMutex);
    gThreads.push_back(&counts);
  }
  ~ThreadCounts() {
    std::lock_guard lock(gMutex);
    add(gRetired, counts);
    std::erase(gThreads, &counts);
  }
};

thread_local ThreadCounts tThread;

}  // namespace

void setKernelCounting(bool on) {
  if (on) {
    std::lock_guard lock(gMutex);
    for (KernelCounts* c : gThreads) *c = {};
    gRetired = {};
  }
  gCounting.store(on, std::memory_order_relaxed);
}

bool kernelCounting() { return gCounting.load(std::memory_order_relaxed); }

KernelCounts kernelCounts() {
  std::lock_guard lock(gMutex);
  KernelCounts sum = gRetired;
  for (const KernelCounts* c : gThreads) add(sum, *c);
  return sum;
}

void countWalk(WalkKind kind, uint64_t segments, uint64_t steps, uint64_t lookups) {
  WalkCounts& w = kind == WalkKind::Collision ? tThread.counts.collision : tThread.counts.transmittance;
  w.walks += 1;
  w.segments += segments;
  w.steps += steps;
  w.lookups += lookups;
}

}  // namespace plume::ref
