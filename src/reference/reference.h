// The independent CPU reference (DESIGN §4.1): unidirectional volumetric path tracing on the
// OpenVDB grid itself. Free flights by delta tracking against the reference's own majorant
// grid, next-event estimation to every light with ratio-tracking transmittance, Henyey–Greenstein
// phase sampling, Russian roulette, `max_bounces`, and the medium's emission gathered at every
// tentative collision of delta tracking (reference/emission.h). Parallel over 16x16 tiles with TBB; each pixel
// owns a PCG32 stream derived from (seed, frame, pixel), so the image does not depend on the
// thread count. Accumulates in double; returns the mean and the per-pixel variance of the mean.
#pragma once

#include "core/image.h"
#include "scene/scene.h"

#include <openvdb/openvdb.h>

#include <cstdint>

namespace plume::ref {

struct ReferenceOptions {
  int frame = 1;
  // The medium's emission grid (scene media[0].emission); null: read from the frame's VDB file.
  openvdb::FloatGrid::ConstPtr emission;
  bool progress = true;   // progress bar on stderr
  int tileSize = 16;
};

struct ReferenceStats {
  double seconds = 0;
  uint64_t samples = 0;           // camera paths
  uint64_t truncatedTracking = 0; // tracking loops stopped by the step cap (should be 0)
  uint64_t trackingSteps = 0;
  double samplesPerSecond() const { return seconds > 0 ? samples / seconds : 0; }
};

// Throws InputError for scene features the reference does not support yet (surfaces), naming the
// scene key.
void checkReferenceSupports(const Scene& scene);

// Renders `scene` at `options.frame` with the medium's density grid `density` (already loaded
// and sanitised). Image metadata: mode, spp, seed, frame, wall time, tracking counters.
Image renderReference(const Scene& scene, openvdb::FloatGrid::ConstPtr density,
                      const ReferenceOptions& options, ReferenceStats* stats = nullptr);

}  // namespace plume::ref
