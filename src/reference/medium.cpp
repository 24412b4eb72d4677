#include "reference/medium.h"

#include "core/error.h"
#include "reference/counters.h"

#include <openvdb/tools/Interpolation.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace plume::ref {
namespace {

int floorDiv(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

glm::dvec3 toGlm(const openvdb::Vec3d& v) { return {v.x(), v.y(), v.z()}; }
openvdb::Vec3d toVdb(const glm::dvec3& v) { return {v.x, v.y, v.z}; }

}  // namespace

struct ReferenceMedium::Walk {
  glm::dvec3 o, d;  // index-space ray; t in world units
  double t = 0, tEnd = 0;
  glm::ivec3 cell{0}, step{0};
  glm::dvec3 tNext{0}, tDelta{0};
};

ReferenceMedium::ReferenceMedium(openvdb::FloatGrid::ConstPtr grid, float densityScale)
    : grid_(std::move(grid)), densityScale_(densityScale) {
  if (!grid_->transform().isLinear()) throw InputError("grid " + grid_->getName() + ": non-linear transform");
  worldToIndex_ = grid_->transform().baseMap()->getAffineMap()->getMat4().inverse();

  openvdb::CoordBBox box = grid_->evalActiveVoxelBoundingBox();
  if (box.empty() || densityScale_ <= 0.0f) return;
  const int S = kCellSize;
  origin_ = box.min() - openvdb::Coord(1);
  for (int a = 0; a < 3; ++a) dims_[a] = floorDiv(box.max()[a] + 1 - origin_[a], S) + 1;
  cells_.assign(size_t(dims_.x) * dims_.y * dims_.z, 0.0f);

  // Cell c covers index coordinates [O + cS, O + (c+1)S); trilinear lookups there read voxels
  // O + cS .. O + (c+1)S inclusive, so an active value (voxel or tile box [lo, hi]) raises the
  // majorant of every cell whose closed voxel window [O + cS, O + cS + S] meets [lo, hi].
  for (auto it = grid_->cbeginValueOn(); it; ++it) {
    const float v = *it;
    if (!(v > 0.0f)) continue;
    openvdb::CoordBBox vb = it.isVoxelValue() ? openvdb::CoordBBox(it.getCoord(), it.getCoord())
                                              : it.getBoundingBox();
    glm::ivec3 c0, c1;
    for (int a = 0; a < 3; ++a) {
      c0[a] = std::max(0, floorDiv(vb.min()[a] - origin_[a] - 1, S));
      c1[a] = std::min(dims_[a] - 1, floorDiv(vb.max()[a] - origin_[a], S));
    }
    const float sigma = v * densityScale_;
    for (int z = c0.z; z <= c1.z; ++z)
      for (int y = c0.y; y <= c1.y; ++y)
        for (int x = c0.x; x <= c1.x; ++x) {
          float& m = cells_[(size_t(z) * dims_.y + y) * dims_.x + x];
          m = std::max(m, sigma);
        }
  }
}

glm::dvec3 ReferenceMedium::worldToIndex(const glm::dvec3& p) const {
  return toGlm(worldToIndex_.transform(toVdb(p)));
}

glm::dvec3 ReferenceMedium::worldDirToIndex(const glm::dvec3& d) const {
  return toGlm(worldToIndex_.transform3x3(toVdb(d)));
}

double ReferenceMedium::sigmaT(const Accessor& acc, const glm::dvec3& world) const {
  glm::dvec3 i = worldToIndex(world);
  return densityScale_ * openvdb::tools::BoxSampler::sample(acc, openvdb::Vec3R(i.x, i.y, i.z));
}

double ReferenceMedium::majorantAtIndex(const glm::dvec3& index) const {
  if (cells_.empty()) return 0.0;
  glm::ivec3 c;
  for (int a = 0; a < 3; ++a) {
    c[a] = int(std::floor((index[a] - origin_[a]) / kCellSize));
    if (c[a] < 0 || c[a] >= dims_[a]) return 0.0;
  }
  return cells_[(size_t(c.z) * dims_.y + c.y) * dims_.x + c.x];
}

bool ReferenceMedium::startWalk(const Ray& ray, double tMax, Walk& w) const {
  if (cells_.empty()) return false;
  w.o = worldToIndex(ray.origin);
  w.d = worldDirToIndex(ray.direction);
  const double S = kCellSize;
  double tEnter = 0.0, tExit = tMax;
  for (int a = 0; a < 3; ++a) {
    const double lo = origin_[a], hi = origin_[a] + dims_[a] * S;
    if (std::abs(w.d[a]) < 1e-300) {
      if (w.o[a] < lo || w.o[a] >= hi) return false;
      continue;
    }
    double ta = (lo - w.o[a]) / w.d[a], tb = (hi - w.o[a]) / w.d[a];
    if (ta > tb) std::swap(ta, tb);
    tEnter = std::max(tEnter, ta);
    tExit = std::min(tExit, tb);
  }
  if (!(tEnter < tExit)) return false;
  w.t = tEnter;
  w.tEnd = tExit;
  const glm::dvec3 p = w.o + tEnter * w.d;
  for (int a = 0; a < 3; ++a) {
    w.cell[a] = std::clamp(int(std::floor((p[a] - origin_[a]) / S)), 0, dims_[a] - 1);
    if (std::abs(w.d[a]) < 1e-300) {
      w.step[a] = 0;
      w.tNext[a] = std::numeric_limits<double>::infinity();
      w.tDelta[a] = std::numeric_limits<double>::infinity();
      continue;
    }
    w.step[a] = w.d[a] > 0 ? 1 : -1;
    const double boundary = origin_[a] + (w.cell[a] + (w.d[a] > 0 ? 1 : 0)) * S;
    w.tNext[a] = (boundary - w.o[a]) / w.d[a];
    w.tDelta[a] = S / std::abs(w.d[a]);
  }
  return true;
}

bool ReferenceMedium::nextSegment(Walk& w, double& t0, double& t1, double& majorant) const {
  if (w.t >= w.tEnd) return false;
  int axis = 0;
  if (w.tNext[1] < w.tNext[axis]) axis = 1;
  if (w.tNext[2] < w.tNext[axis]) axis = 2;
  t0 = w.t;
  t1 = std::min(w.tNext[axis], w.tEnd);
  majorant = cells_[(size_t(w.cell.z) * dims_.y + w.cell.y) * dims_.x + w.cell.x];
  w.t = t1;
  w.cell[axis] += w.step[axis];
  w.tNext[axis] += w.tDelta[axis];
  if (w.cell[axis] < 0 || w.cell[axis] >= dims_[axis]) w.t = w.tEnd;
  return true;
}

template <typename OnCollision>
void ReferenceMedium::trackMajorants(WalkKind kind, const Ray& ray, double tMax, Pcg32& rng, const Accessor& acc,
                                     TrackingStats& stats, OnCollision&& onCollision) const {
  Walk w;
  if (!startWalk(ray, tMax, w)) return;
  uint64_t steps = 0, segments = 0, lookups = 0;  // lookups and segments: the kernel benchmark's only
  double a, b, maj;
  bool going = true;
  while (going && nextSegment(w, a, b, maj)) {
    ++segments;
    if (maj <= 0.0) continue;
    for (double t = a;;) {
      if (++steps > kMaxTrackingSteps) {
        stats.truncated.fetch_add(1, std::memory_order_relaxed);
        going = false;
        break;
      }
      t -= std::log(1.0 - double(rng.uniform())) / maj;
      if (t >= b) break;
      ++lookups;
      const glm::dvec3 p = w.o + t * w.d;
      const double sigma = densityScale_ * openvdb::tools::BoxSampler::sample(acc, openvdb::Vec3R(p.x, p.y, p.z));
      if (!onCollision(t, sigma, maj)) {
        going = false;
        break;
      }
    }
  }
  stats.steps.fetch_add(steps, std::memory_order_relaxed);
  if (kernelCounting()) countWalk(kind, segments, std::min(steps, kMaxTrackingSteps), lookups);
}

bool ReferenceMedium::sampleCollision(const Ray& ray, double tMax, Pcg32& rng, const Accessor& acc,
                                      double& tHit, TrackingStats& stats) const {
  bool hit = false;
  trackMajorants(WalkKind::Collision, ray, tMax, rng, acc, stats, [&](double t, double sigma, double maj) {
    if (!(double(rng.uniform()) * maj < sigma)) return true;  // a null collision: go on
    tHit = t;  // real collision with probability sigma / maj
    hit = true;
    return false;
  });
  return hit;
}

bool ReferenceMedium::sampleCollision(const Ray& ray, double tMax, Pcg32& rng, const Accessor& acc, double& tHit,
                                      TrackingStats& stats,
                                      const std::function<void(double, double, double)>& onTentative) const {
  bool hit = false;
  trackMajorants(WalkKind::Collision, ray, tMax, rng, acc, stats, [&](double t, double sigma, double maj) {
    onTentative(t, sigma, maj);
    if (!(double(rng.uniform()) * maj < sigma)) return true;
    tHit = t;
    hit = true;
    return false;
  });
  return hit;
}

double ReferenceMedium::ratioTracking(const Ray& ray, double tMax, Pcg32& rng, const Accessor& acc,
                                      TrackingStats& stats) const {
  double transmittance = 1.0;
  trackMajorants(WalkKind::Transmittance, ray, tMax, rng, acc, stats, [&](double, double sigma, double maj) {
    transmittance *= std::max(0.0, 1.0 - sigma / maj);  // ratio tracking weight per tentative collision
    if (transmittance < kRouletteTransmittance) {
      // Russian roulette (unbiased: E[T'] = q * T / q = T): go on with probability
      // q = T / kRouletteTransmittance carrying T / q, else stop with 0.
      const double q = transmittance / kRouletteTransmittance;
      transmittance = double(rng.uniform()) < q ? kRouletteTransmittance : 0.0;
    }
    return transmittance > 0.0;
  });
  return transmittance;
}

}  // namespace plume::ref
