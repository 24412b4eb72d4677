// The CPU reference's view of a medium: the OpenVDB grid itself (trilinear lookups with
// openvdb::tools::BoxSampler, DESIGN §2) and the reference's own majorant grid, built directly
// from the tree's active values — never from the GPU bake, so that a bug in the bake cannot
// hide in both (DESIGN §1).
//
// Tracking runs in index space with the ray parameter t in world units: the world ray
// o + t d (|d| = 1) maps to index space as o' + t d' with d' = A^-1 d for the grid's affine map
// A, so sigma_t = densityScale * d(x) stays "per world unit" along t.
#pragma once

#include "reference/counters.h"
#include "reference/ref_rng.h"

#include <glm/vec3.hpp>
#include <openvdb/openvdb.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <vector>

namespace plume::ref {

struct Ray {
  glm::dvec3 origin;     // world
  glm::dvec3 direction;  // world, unit length
};

// Counters shared by all threads; reported with every render (no silent caps).
struct TrackingStats {
  std::atomic<uint64_t> truncated{0};  // tracking loops stopped by kMaxTrackingSteps
  std::atomic<uint64_t> steps{0};
};

class ReferenceMedium {
 public:
  static constexpr int kCellSize = 8;                  // voxels per majorant cell and axis
  static constexpr uint64_t kMaxTrackingSteps = 1u << 22;
  // Ratio tracking plays Russian roulette once its transmittance falls below this (medium.cpp).
  static constexpr double kRouletteTransmittance = 0.1;

  ReferenceMedium(openvdb::FloatGrid::ConstPtr grid, float densityScale);

  using Accessor = openvdb::FloatGrid::ConstAccessor;  // one per thread
  Accessor accessor() const { return grid_->getConstAccessor(); }

  bool empty() const { return cells_.empty(); }
  // sigma_t at a world point.
  double sigmaT(const Accessor& acc, const glm::dvec3& world) const;
  // Majorant of sigma_t over the cell holding an index-space point (0 outside the grid).
  double majorantAtIndex(const glm::dvec3& index) const;

  // Delta tracking: the first real collision in (0, tMax); false if the ray gets through.
  bool sampleCollision(const Ray& ray, double tMax, Pcg32& rng, const Accessor& acc, double& tHit,
                       TrackingStats& stats) const;
  // Delta tracking as sampleCollision that also hands every tentative collision, the real one
  // included, to onTentative(t, sigma_t, majorant) before deciding it (emission estimators sum
  // sigma_t Le / majorant over them).
  bool sampleCollision(const Ray& ray, double tMax, Pcg32& rng, const Accessor& acc, double& tHit,
                       TrackingStats& stats, const std::function<void(double, double, double)>& onTentative) const;
  // Ratio tracking estimate of the transmittance over (0, tMax) (unbiased, in [0, 1]), with
  // Russian roulette on small transmittance: a walk through a dense medium stops soon after T
  // falls below kRouletteTransmittance instead of walking on until T underflows to 0.
  double ratioTracking(const Ray& ray, double tMax, Pcg32& rng, const Accessor& acc,
                       TrackingStats& stats) const;

  glm::dvec3 worldToIndex(const glm::dvec3& p) const;
  glm::dvec3 worldDirToIndex(const glm::dvec3& d) const;

 private:
  // A walk over the majorant cells that a ray crosses: [t0, t1) segments with one majorant.
  struct Walk;
  bool startWalk(const Ray& ray, double tMax, Walk& walk) const;
  bool nextSegment(Walk& walk, double& t0, double& t1, double& majorant) const;
  // The one majorant walk (pbrt-v4's SampleT_maj): the tentative collisions of each cell's
  // majorant Poisson process (exponential steps, memoryless, so each cell restarts at its entry)
  // handed to onCollision(t, sigma_t(t), majorant), which returns false to stop. Truncation by
  // kMaxTrackingSteps is counted in stats and ends the walk (no silent caps).
  template <typename OnCollision>
  void trackMajorants(WalkKind kind, const Ray& ray, double tMax, Pcg32& rng, const Accessor& acc, TrackingStats& stats,
                      OnCollision&& onCollision) const;

  openvdb::FloatGrid::ConstPtr grid_;
  float densityScale_;
  openvdb::math::Mat4d worldToIndex_;  // affine (checked), OpenVDB's row-vector convention
  openvdb::Coord origin_;              // index coordinate of cell (0,0,0)'s lower corner
  glm::ivec3 dims_{0};                 // cells per axis
  std::vector<float> cells_;           // majorant of sigma_t per cell
};

}  // namespace plume::ref
