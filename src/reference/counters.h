// The CPU reference's event counts for the kernel benchmark (`plume bench --kernels`,
// bench/kernels.h), counted by the reference's own walk (medium.cpp) and independent of the
// GPU's (shaders/shared/kernel_counters.h counts the same events there). Each walk counts in
// locals; only while counting is on does it add them to its thread's totals (one relaxed load
// per walk otherwise), and kernelCounts() sums the threads' totals after a render.
#pragma once

#include <cstdint>

namespace plume::ref {

enum class WalkKind { Collision, Transmittance };  // delta tracking; ratio tracking (NEE)

struct WalkCounts {
  uint64_t walks = 0;     // walks that entered the majorant grid's box
  uint64_t segments = 0;  // majorant cells crossed (empty ones included)
  uint64_t steps = 0;     // tentative collisions drawn, the one past a cell's end included
  uint64_t lookups = 0;   // density lookups (tentative collisions inside a cell)
};

struct KernelCounts {
  WalkCounts collision, transmittance;
};

// Turns counting on or off; turning it on zeroes every thread's totals. Not during a render.
void setKernelCounting(bool on);
bool kernelCounting();
// The totals over all threads since counting was turned on. Not during a render.
KernelCounts kernelCounts();
// Adds one walk to the calling thread's totals (medium.cpp, only while counting).
void countWalk(WalkKind kind, uint64_t segments, uint64_t steps, uint64_t lookups);

}  // namespace plume::ref
