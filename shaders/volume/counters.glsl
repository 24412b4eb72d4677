// The kernel benchmark's counters in the majorant walk (shared/kernel_counters.h), compiled only
// with PLUME_KERNEL_COUNTERS (`plume bench --kernels`). Each lane counts its own events in
// registers; a loop iteration of the subgroup is counted once, by the elected lane; one
// subgroupAdd and one atomic per word and subgroup when a walk ends, never in a loop.
// Requires volume/bindings.glsl.
#ifndef PLUME_VOLUME_COUNTERS_GLSL
#define PLUME_VOLUME_COUNTERS_GLSL

#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require

#include "../shared/kernel_counters.h"

struct VolKc {
  uint segments;
  uint segmentIters;
  uint stepIters;
  uint lookups;
  uint lookupIters;
};

VolKc vol_kc_start() { return VolKc(0u, 0u, 0u, 0u, 0u); }
void vol_kc_segment(inout VolKc k) {
  k.segments += 1u;
  if (subgroupElect()) k.segmentIters += 1u;
}
void vol_kc_step(inout VolKc k) {
  if (subgroupElect()) k.stepIters += 1u;
}
void vol_kc_lookup(inout VolKc k) {
  k.lookups += 1u;
  if (subgroupElect()) k.lookupIters += 1u;
}

void vol_kc_add(uint word, uint n) {
  uint sum = subgroupAdd(n);
  if (subgroupElect() && sum != 0u) atomicAdd(volCounters[word], sum);
}

// At the end of a walk of `tracker` that entered the volume, with its `steps`.
void vol_kc_flush(uint tracker, VolKc k, uint steps) {
  uint base = KC_BASE + tracker * KC_PER_TRACKER;
  vol_kc_add(base + KC_WALKS, 1u);
  vol_kc_add(base + KC_SEGMENTS, k.segments);
  vol_kc_add(base + KC_SEGMENT_ITERS, k.segmentIters);
  vol_kc_add(base + KC_STEPS, steps);
  vol_kc_add(base + KC_STEP_ITERS, k.stepIters);
  vol_kc_add(base + KC_LOOKUPS, k.lookups);
  vol_kc_add(base + KC_LOOKUP_ITERS, k.lookupIters);
}

#endif
