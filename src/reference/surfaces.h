// The CPU reference's surfaces (DESIGN §2 "Surfaces", §4.3): the scene's triangles intersected
// with Embree directly (geometry/bvh.h EmbreeScene: its own rtcIntersect1 / rtcOccluded1 calls,
// never the flattened tree the shaders traverse), their materials as shared/bsdf.h BSDFs, and the
// emissive triangles as lights: Le leaves a triangle's front side (counter-clockwise winding),
// and one CDF over every emissive triangle picks one in proportion to its power (area times the
// mean of Le's channels), then a point uniformly in it (pdf per area = P(triangle) / area).
#pragma once

#include "geometry/bvh.h"
#include "geometry/mesh.h"
#include "reference/medium.h"
#include "scene/scene.h"
#include "shaders/shared/bsdf.h"

#include <glm/vec3.hpp>

#include <cstdint>
#include <memory>
#include <vector>

namespace plume::ref {

struct SurfaceHit {
  double t = 0.0;         // along the ray, world units
  glm::dvec3 point{0.0};
  glm::dvec3 normal{0.0};   // unit geometric normal of the front side
  glm::dvec3 shading{0.0};  // unit shading normal (interpolated `vn`, else the geometric one)
  uint32_t triangle = 0;
  uint32_t surface = 0;     // index into scene.surfaces
};

struct EmitterSample {
  glm::dvec3 point{0.0};
  glm::dvec3 normal{0.0};    // front side
  glm::dvec3 radiance{0.0};  // Le of the front side
  double pdfArea = 0.0;      // per unit area, the triangle's choice included
};

class ReferenceSurfaces {
 public:
  // Loads the scene's surfaces (geo::loadSceneSurfaces: InputError naming the file and line, or the
  // scene key) and builds the Embree scene.
  explicit ReferenceSurfaces(const Scene& scene);

  // Closest hit with t in (0, tMax]; false on a miss.
  bool intersect(const Ray& ray, double tMax, SurfaceHit& hit) const;
  // Whether any triangle lies on the ray with t in (0, tMax] (shadow rays).
  bool occluded(const Ray& ray, double tMax) const;

  const shared::Bsdf& bsdf(const SurfaceHit& hit) const { return bsdfs_[hit.surface]; }
  // Le seen by a ray of direction `dir` arriving at the hit: the surface's emission on the front
  // side, 0 on the back (DESIGN §2).
  glm::dvec3 emitted(const SurfaceHit& hit, const glm::dvec3& dir) const;

  size_t triangleCount() const { return normals_.size(); }
  bool hasEmitters() const { return !emitters_.empty(); }
  size_t emitterCount() const { return emitters_.size(); }
  // A point on an emissive triangle (u in [0, 1)^3: one for the triangle, two inside it).
  EmitterSample sampleEmitter(double uTriangle, double u1, double u2) const;
  // The area density with which sampleEmitter picks a point of `triangle` (0: not an emitter).
  double emitterPdfArea(uint32_t triangle) const { return emitterPdf_[triangle]; }

  // A ray's origin at a surface point, pushed off the surface to `dir`'s side of the geometric
  // normal so that the next intersection cannot find the same triangle (Embree intersects in
  // float: the offset is relative to the point's magnitude).
  static glm::dvec3 offsetOrigin(const glm::dvec3& point, const glm::dvec3& normal, const glm::dvec3& dir);
  static double offsetLength(const glm::dvec3& point);
  static constexpr double kRelativeOffset = 1e-4;

 private:
  geo::TriangleMesh mesh_;                // world space
  std::vector<uint32_t> triangleSurface_;
  std::vector<glm::dvec3> normals_;       // per triangle: unit geometric normal (front side)
  std::vector<shared::Bsdf> bsdfs_;       // per surface
  std::vector<glm::dvec3> emission_;      // per surface: Le of the front side
  std::vector<uint32_t> emitters_;        // the emissive triangles
  std::vector<double> emitterCdf_;        // emitterCdf_[i + 1] = P(emitter <= i)
  std::vector<double> emitterPdf_;        // per triangle: area density, 0 if it does not emit
  std::unique_ptr<geo::EmbreeScene> embree_;
};

}  // namespace plume::ref
