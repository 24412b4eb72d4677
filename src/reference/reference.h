// The independent CPU reference (DESIGN §4.1): unidirectional volumetric path tracing on the
// OpenVDB grid itself. Free flights by delta tracking against the reference's own majorant
// grid, next-event estimation to every light with ratio-tracking transmittance, Henyey–Greenstein
// phase sampling, Russian roulette, `max_bounces`, and the medium's emission gathered at every
// tentative collision of delta tracking (reference/emission.h), and surfaces (reference/surfaces.h):
// a surface hit is one more scattering vertex (BSDF x cosine), emissive triangles are lights
// sampled by area and hit by phase/BSDF-sampled paths, the two combined by MIS (power heuristic);
// shadow rays multiply ratio-tracking transmittance by Embree's any-hit visibility. Parallel over 16x16 tiles with TBB; each pixel
// owns a PCG32 stream derived from (seed, frame, pixel), so the image does not depend on the
// thread count. Accumulates in double; returns the mean and the per-pixel variance of the mean.
#pragma once

#include "core/image.h"
#include "reference/surfaces.h"
#include "scene/scene.h"

#include <openvdb/openvdb.h>

#include <cstdint>
#include <memory>

namespace plume::ref {

// Which strategies reach emissive triangles. Each alone is unbiased, so a test can check that they
// agree with each other and with MIS; the commands always use Mis.
enum class EmitterStrategy { Mis, LightSamplingOnly, DirectionSamplingOnly };

struct ReferenceOptions {
  int frame = 1;
  // The medium's emission grid (scene media[0].emission); null: read from the frame's VDB file.
  openvdb::FloatGrid::ConstPtr emission;
  // The scene's surfaces, loaded once for every frame; null: loaded by renderReference when the
  // scene has any (a scene without surfaces builds no Embree scene).
  std::shared_ptr<const ReferenceSurfaces> surfaces;
  EmitterStrategy emitterStrategy = EmitterStrategy::Mis;
  bool progress = true;   // progress bar on stderr
  int tileSize = 16;
};

struct ReferenceStats {
  double seconds = 0;
  uint64_t samples = 0;           // camera paths
  uint64_t truncatedTracking = 0; // tracking loops stopped by the step cap (should be 0)
  uint64_t trackingSteps = 0;
  size_t surfaceTriangles = 0;    // 0: no surfaces (and no Embree scene)
  size_t emissiveTriangles = 0;
  double samplesPerSecond() const { return seconds > 0 ? samples / seconds : 0; }
};

// Throws InputError for scene features the reference does not support, naming the scene key (none
// today: the reference renders every feature of DESIGN §9, surfaces included).
void checkReferenceSupports(const Scene& scene);

// Renders `scene` at `options.frame` with the medium's density grid `density` (already loaded
// and sanitised). Image metadata: mode, spp, seed, frame, wall time, tracking counters.
Image renderReference(const Scene& scene, openvdb::FloatGrid::ConstPtr density,
                      const ReferenceOptions& options, ReferenceStats* stats = nullptr);

}  // namespace plume::ref
