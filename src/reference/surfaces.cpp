#include "reference/surfaces.h"

#include "geometry/scene_mesh.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace plume::ref {

using glm::dvec3;
namespace sh = plume::shared;

ReferenceSurfaces::ReferenceSurfaces(const Scene& scene) {
  geo::SceneMesh sm = geo::loadSceneSurfaces(scene);
  mesh_ = std::move(sm.mesh);
  triangleSurface_ = std::move(sm.triangleSurface);
  for (const Surface& s : scene.surfaces) {
    bsdfs_.push_back(geo::surfaceBsdf(s));
    emission_.push_back(dvec3(s.emission));
  }
  const size_t n = mesh_.triangleCount();
  normals_.resize(n);
  emitterPdf_.assign(n, 0.0);
  std::vector<double> areas(n);
  for (size_t i = 0; i < n; ++i) {
    const glm::uvec3 v = mesh_.triangles[i];
    const dvec3 p0(mesh_.positions[v.x]), p1(mesh_.positions[v.y]), p2(mesh_.positions[v.z]);
    normals_[i] = glm::normalize(glm::cross(p1 - p0, p2 - p0));  // counter-clockwise: the front
    areas[i] = 0.5 * geo::doubleArea(mesh_, i);
  }
  // Power of an emitter: area x pi x Le, in proportion to area x mean(Le).
  emitterCdf_.push_back(0.0);
  for (size_t i = 0; i < n; ++i) {
    const dvec3& le = emission_[triangleSurface_[i]];
    const double power = areas[i] * (le.x + le.y + le.z) / 3.0;
    if (!(power > 0.0)) continue;
    emitters_.push_back(uint32_t(i));
    emitterCdf_.push_back(emitterCdf_.back() + power);
  }
  const double total = emitterCdf_.back();
  for (size_t k = 0; k < emitters_.size(); ++k) {
    const uint32_t i = emitters_[k];
    emitterPdf_[i] = (emitterCdf_[k + 1] - emitterCdf_[k]) / total / areas[i];
  }
  for (double& c : emitterCdf_) c /= total > 0.0 ? total : 1.0;
  embree_ = std::make_unique<geo::EmbreeScene>(mesh_);
}

double ReferenceSurfaces::offsetLength(const dvec3& point) {
  return kRelativeOffset * (1.0 + std::max({std::abs(point.x), std::abs(point.y), std::abs(point.z)}));
}

dvec3 ReferenceSurfaces::offsetOrigin(const dvec3& point, const dvec3& normal, const dvec3& dir) {
  const double side = glm::dot(normal, dir) < 0.0 ? -1.0 : 1.0;
  return point + (side * offsetLength(point)) * normal;
}

bool ReferenceSurfaces::intersect(const Ray& ray, double tMax, SurfaceHit& hit) const {
  const float tFar = float(std::min(tMax, double(std::numeric_limits<float>::max())));
  const sh::BvhHit h = embree_->intersect(glm::vec3(ray.origin), glm::vec3(ray.direction), 0.0f, tFar);
  if (h.prim == sh::BVH_NONE) return false;
  hit.t = h.t;
  hit.point = ray.origin + hit.t * ray.direction;
  hit.triangle = h.prim;
  hit.surface = triangleSurface_[h.prim];
  hit.normal = normals_[h.prim];
  hit.shading = hit.normal;
  if (mesh_.hasNormals(h.prim)) {
    // Embree's barycentrics: p = (1 - u - v) p0 + u p1 + v p2.
    const glm::uvec3 k = mesh_.triangleNormals[h.prim];
    const dvec3 ns = (1.0 - h.u - h.v) * dvec3(mesh_.normals[k.x]) + double(h.u) * dvec3(mesh_.normals[k.y]) +
                     double(h.v) * dvec3(mesh_.normals[k.z]);
    const double len = glm::length(ns);
    if (len > 0.0) hit.shading = ns / len;
  }
  return true;
}

bool ReferenceSurfaces::occluded(const Ray& ray, double tMax) const {
  const float tFar = float(std::min(tMax, double(std::numeric_limits<float>::max())));
  return embree_->occluded(glm::vec3(ray.origin), glm::vec3(ray.direction), 0.0f, tFar);
}

dvec3 ReferenceSurfaces::emitted(const SurfaceHit& hit, const dvec3& dir) const {
  return glm::dot(hit.normal, dir) < 0.0 ? emission_[hit.surface] : dvec3(0.0);
}

EmitterSample ReferenceSurfaces::sampleEmitter(double uTriangle, double u1, double u2) const {
  // The first emitter whose cumulative probability exceeds uTriangle.
  const size_t k = std::min(size_t(std::upper_bound(emitterCdf_.begin() + 1, emitterCdf_.end(), uTriangle) -
                                   emitterCdf_.begin()) - 1,
                            emitters_.size() - 1);
  const uint32_t i = emitters_[k];
  const glm::uvec3 v = mesh_.triangles[i];
  // Uniform in the triangle: barycentrics (1 - sqrt(u1), u2 sqrt(u1) ...) (pbrt's square-root map).
  const double r = std::sqrt(u1);
  const double b1 = r * (1.0 - u2), b2 = r * u2;
  EmitterSample s;
  s.point = (1.0 - b1 - b2) * dvec3(mesh_.positions[v.x]) + b1 * dvec3(mesh_.positions[v.y]) +
            b2 * dvec3(mesh_.positions[v.z]);
  s.normal = normals_[i];
  s.radiance = emission_[triangleSurface_[i]];
  s.pdfArea = emitterPdf_[i];
  return s;
}

}  // namespace plume::ref
