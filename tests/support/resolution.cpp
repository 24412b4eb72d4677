#include "support/resolution.h"

#include "geometry/bvh.h"
#include "geometry/scene_mesh.h"

#include <glm/glm.hpp>
#include <openvdb/tools/Interpolation.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <memory>

namespace plume::test {

namespace {

// The reference's camera (reference/reference.cpp cameraRay): a point (u, v) of pixel (px, py).
struct CameraRays {
  glm::dvec3 position, forward, right, up;
  double tanHalfY, aspect;
  int width, height;
  CameraRays(const Camera& cam, int frame) {
    const CameraPose pose = cam.poseAt(frame);
    position = glm::dvec3(pose.position);
    forward = glm::normalize(glm::dvec3(pose.lookAt - pose.position));
    right = glm::normalize(glm::cross(forward, glm::dvec3(pose.up)));
    up = glm::cross(right, forward);
    tanHalfY = std::tan(glm::radians(double(pose.fovY)) * 0.5);
    aspect = double(cam.width) / cam.height;
    width = cam.width;
    height = cam.height;
  }
  glm::dvec3 direction(int px, int py, double u, double v) const {
    const double sx = (2.0 * (px + u) / width - 1.0) * tanHalfY * aspect;
    const double sy = (1.0 - 2.0 * (py + v) / height) * tanHalfY;
    return glm::normalize(forward + sx * right + sy * up);
  }
};

// Optical depth of a world ray through the trilinear density (midpoint rule, a quarter voxel a
// step, inside the active box grown by one voxel: the interpolation's support).
class OpticalDepth {
 public:
  OpticalDepth(const openvdb::FloatGrid& grid, double scale) : grid_(grid), scale_(scale) {
    const openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
    empty_ = box.empty();
    lo_ = glm::dvec3(box.min().x(), box.min().y(), box.min().z()) - 1.0;
    hi_ = glm::dvec3(box.max().x(), box.max().y(), box.max().z()) + 1.0;
  }
  double operator()(const glm::dvec3& o, const glm::dvec3& d) const {
    if (empty_ || scale_ <= 0.0) return 0.0;
    const openvdb::Vec3d a = grid_.transform().worldToIndex(openvdb::Vec3d(o.x, o.y, o.z));
    const openvdb::Vec3d b = grid_.transform().worldToIndex(openvdb::Vec3d(o.x + d.x, o.y + d.y, o.z + d.z));
    const glm::dvec3 oi(a.x(), a.y(), a.z()), di = glm::dvec3(b.x(), b.y(), b.z()) - oi;  // per world unit
    double t0 = 0.0, t1 = 1e30;
    for (int k = 0; k < 3; ++k) {
      if (di[k] == 0.0) {
        if (oi[k] < lo_[k] || oi[k] > hi_[k]) return 0.0;
        continue;
      }
      double ta = (lo_[k] - oi[k]) / di[k], tb = (hi_[k] - oi[k]) / di[k];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
    }
    if (!(t0 < t1)) return 0.0;
    const double h = 0.25 / glm::length(di);
    auto acc = grid_.getConstAccessor();
    double tau = 0.0;
    for (double t = t0 + 0.5 * h; t < t1; t += h) {
      const glm::dvec3 p = oi + t * di;
      tau += std::max(0.0, double(openvdb::tools::BoxSampler::sample(acc, openvdb::Vec3R(p.x, p.y, p.z))));
    }
    return scale_ * tau * h;
  }

 private:
  const openvdb::FloatGrid& grid_;
  double scale_;
  bool empty_ = true;
  glm::dvec3 lo_{0.0}, hi_{0.0};
};

}  // namespace

int ResolutionMap::count(PixelResolution r) const { return int(std::count(pixels.begin(), pixels.end(), r)); }

std::vector<bool> ResolutionMap::unresolvedMask() const {
  std::vector<bool> mask(pixels.size());
  for (size_t i = 0; i < pixels.size(); ++i) mask[i] = pixels[i] == PixelResolution::Unresolved;
  return mask;
}

ResolutionMap referenceResolution(const Scene& scene, const openvdb::FloatGrid& density, int spp, int frame,
                                  int raysPerAxis, double minCollisions) {
  const CameraRays cam(scene.camera, frame);
  const OpticalDepth depth(density, scene.medium().densityScale);
  // With surfaces, a camera ray that meets one has a vertex there for sure (when the medium
  // has none before it).
  std::unique_ptr<geo::EmbreeScene> surfaces;
  if (!scene.surfaces.empty()) surfaces = std::make_unique<geo::EmbreeScene>(geo::loadSceneSurfaces(scene).mesh);
  auto vertexProbability = [&](const glm::dvec3& d) {
    if (surfaces && surfaces->occluded(glm::vec3(cam.position), glm::vec3(d), 0.0f, 1e30f)) return 1.0;
    return -std::expm1(-depth(cam.position, d));
  };
  ResolutionMap map;
  map.width = cam.width;
  map.height = cam.height;
  const int n = cam.width * cam.height;
  map.pixels.assign(size_t(n), PixelResolution::Empty);
  map.collisionProbability.assign(size_t(n), 0.0);
  tbb::parallel_for(tbb::blocked_range<int>(0, n), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i != r.end(); ++i) {
      const int px = i % cam.width, py = i / cam.width;
      double p = 0.0;
      bool near = false;
      for (int a = 0; a < raysPerAxis; ++a) {
        for (int b = 0; b < raysPerAxis; ++b) {
          const double u = (a + 0.5) / raysPerAxis, v = (b + 0.5) / raysPerAxis;
          p += vertexProbability(cam.direction(px, py, u, v));
          near |= depth(cam.position, cam.direction(px, py, 2.0 * u - 0.5, 2.0 * v - 0.5)) > 0.0;
        }
      }
      p /= double(raysPerAxis) * raysPerAxis;
      map.collisionProbability[size_t(i)] = p;
      if (p * spp >= minCollisions) {
        map.pixels[size_t(i)] = PixelResolution::Resolved;
      } else if (p > 0.0 || near) {
        map.pixels[size_t(i)] = PixelResolution::Unresolved;
      }
    }
  });
  return map;
}

}  // namespace plume::test
