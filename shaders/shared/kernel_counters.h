// The kernel benchmark's event counters (`plume bench --kernels`, src/bench/kernels.h): compiled
// into the majorant walk (volume/walk.glsl) only with PLUME_KERNEL_COUNTERS, which only the
// benchmark asks for (FeatureSet::kernelCounters), so normal renders run none of it. They live
// in the volume's counter buffer (BIND_VOLUME_COUNTERS) after its own words, one block of
// KC_PER_TRACKER words per tracker (VOL_TRACK_* of volume/walk.glsl).
//
// Per tracker: walks that entered the volume's box; DDA segments (per lane) and the subgroup
// iterations of the segment loop that had any lane active (subgroupElect); tracking steps
// (tentative collisions drawn, per lane, the draw that leaves a segment included) and their
// subgroup iterations; density lookups (tentative collisions inside a segment) and theirs.
// lanes / iterations is the mean number of active lanes per subgroup in that loop, and
// steps - lookups <= segments (each segment ends with at most one step past its end).
#ifndef PLUME_SHARED_KERNEL_COUNTERS_H
#define PLUME_SHARED_KERNEL_COUNTERS_H

#include "common.h"

PLUME_NS_BEGIN

const uint KC_BASE = 4u;          // volCounters[0..3]: the volume's own (step-cap truncations)
const uint KC_TRACKERS = 8u;      // VOL_TRACK_DELTA .. VOL_TRACK_RESIDUAL_RATIO
const uint KC_PER_TRACKER = 8u;
const uint KC_WALKS = 0u;
const uint KC_SEGMENTS = 1u;
const uint KC_SEGMENT_ITERS = 2u;
const uint KC_STEPS = 3u;
const uint KC_STEP_ITERS = 4u;
const uint KC_LOOKUPS = 5u;
const uint KC_LOOKUP_ITERS = 6u;
const uint KC_WORDS = KC_BASE + KC_TRACKERS * KC_PER_TRACKER;  // words of the counter buffer

PLUME_NS_END

#endif
