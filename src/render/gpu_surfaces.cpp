#include "render/gpu_surfaces.h"

#include "core/error.h"
#include "core/log.h"
#include "geometry/scene_mesh.h"
#include "shaders/shared/bindings.h"
#include "shaders/shared/surface_types.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

namespace plume {
namespace {

template <typename T>
gpu::Buffer upload(gpu::Context& ctx, const std::vector<T>& data, const char* name) {
  const VkDeviceSize bytes = std::max<VkDeviceSize>(sizeof(T), data.size() * sizeof(T));
  if (bytes > ctx.limits().maxStorageBufferRange) {
    throw InputError(strf("surfaces: the %s need %.0f MiB, more than this device's storage buffers hold (%.0f MiB)",
                          name, double(bytes) / 1048576.0, double(ctx.limits().maxStorageBufferRange) / 1048576.0));
  }
  gpu::Buffer b(ctx, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, name);
  if (!data.empty()) b.upload(data.data(), data.size() * sizeof(T));
  return b;
}

}  // namespace

std::vector<shared::GpuEmitterAlias> emitterAliasTable(const std::vector<double>& weights,
                                                const std::vector<uint32_t>& triangles) {
  const size_t n = weights.size();
  double total = 0.0;
  for (double w : weights) total += w;
  std::vector<double> scaled(n);
  std::vector<size_t> small, large;
  for (size_t i = 0; i < n; ++i) {
    scaled[i] = weights[i] / total * double(n);
    (scaled[i] < 1.0 ? small : large).push_back(i);
  }
  std::vector<shared::GpuEmitterAlias> table(n);
  for (size_t i = 0; i < n; ++i) table[i] = {1.0f, uint32_t(i), triangles[i], 0.0f};
  while (!small.empty() && !large.empty()) {
    const size_t s = small.back(), l = large.back();
    small.pop_back();
    table[s].keep = float(scaled[s]);
    table[s].alias = uint32_t(l);
    scaled[l] -= 1.0 - scaled[s];
    if (scaled[l] < 1.0) {
      large.pop_back();
      small.push_back(l);
    }
  }
  return table;  // the entries left in either list keep themselves (probability 1, up to rounding)
}

GpuSurfaces::GpuSurfaces(gpu::Context& ctx, const Scene& scene) {
  const geo::SceneMesh sm = geo::loadSceneSurfaces(scene);
  const geo::TriangleMesh& mesh = sm.mesh;
  geo::FlatBvh bvh = geo::buildBvh(mesh);
  stats_ = bvh.stats;
  const auto start = std::chrono::steady_clock::now();

  std::vector<shared::GpuSurfaceMaterial> materials;
  for (const Surface& s : scene.surfaces) {
    shared::GpuSurfaceMaterial m{};
    m.bsdf = geo::surfaceBsdf(s);
    m.emission = s.emission;
    materials.push_back(m);
  }
  std::vector<shared::GpuSurfaceTriangle> triangles(mesh.triangleCount());
  std::vector<double> power;
  std::vector<double> area;
  std::vector<uint32_t> emitters;
  for (size_t i = 0; i < mesh.triangleCount(); ++i) {
    shared::GpuSurfaceTriangle& t = triangles[i];
    const glm::uvec3 v = mesh.triangles[i];
    t.v0 = mesh.positions[v.x];
    t.v1 = mesh.positions[v.y];
    t.v2 = mesh.positions[v.z];
    t.surface = sm.triangleSurface[i];
    if (mesh.hasNormals(i)) {
      const glm::uvec3 k = mesh.triangleNormals[i];
      t.hasNormals = 1u;
      t.n0 = mesh.normals[k.x];
      t.n1 = mesh.normals[k.y];
      t.n2 = mesh.normals[k.z];
    }
    const glm::vec3 le = scene.surfaces[t.surface].emission;
    const double a = 0.5 * geo::doubleArea(mesh, i);
    const double p = a * (double(le.x) + double(le.y) + double(le.z)) / 3.0;
    if (p > 0.0) {
      emitterSummary_.push_back({(t.v0 + t.v1 + t.v2) / 3.0f, glm::normalize(glm::cross(t.v1 - t.v0, t.v2 - t.v0)), p});
      emitters.push_back(uint32_t(i));
      power.push_back(p);
      area.push_back(a);
    }
  }
  double total = 0.0;
  for (double p : power) total += p;
  for (size_t k = 0; k < emitters.size(); ++k) triangles[emitters[k]].lightPdf = float(power[k] / total / area[k]);
  emitterCount_ = uint32_t(emitters.size());

  nodes_ = upload(ctx, bvh.nodes, "BVH nodes");
  bvhTriangles_ = upload(ctx, bvh.triangles, "BVH triangles");
  triangles_ = upload(ctx, triangles, "surface triangles");
  materials_ = upload(ctx, materials, "surface materials");
  emitters_ = upload(ctx, emitters.empty() ? std::vector<shared::GpuEmitterAlias>{} : emitterAliasTable(power, emitters),
                     "emitter table");
  uploadMs_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  logInfo(strf("surfaces: %zu triangles (%u emissive), BVH %zu nodes, %.1f bytes/triangle on the device; built in %.0f ms",
               mesh.triangleCount(), emitterCount_, stats_.nodes, stats_.bytesPerTriangle(), stats_.buildMs));
}

void GpuSurfaces::bind(gpu::DescriptorSet& set, uint32_t shift) const {
  set.bind(shared::BIND_BVH_NODES + shift, nodes_);
  set.bind(shared::BIND_BVH_TRIANGLES + shift, bvhTriangles_);
  set.bind(shared::BIND_SURF_TRIANGLES + shift, triangles_);
  set.bind(shared::BIND_SURF_MATERIALS + shift, materials_);
  set.bind(shared::BIND_EMITTERS + shift, emitters_);
}

double GpuSurfaces::emitterPowerAt(glm::vec3 p) const {
  double sum = 0.0;
  for (const EmitterSummary& e : emitterSummary_) {
    const glm::dvec3 d = glm::dvec3(p) - glm::dvec3(e.centroid);
    const double r2 = std::max(1e-12, glm::dot(d, d));
    const double cosine = std::max(0.0, glm::dot(d, glm::dvec3(e.normal)) / std::sqrt(r2));
    sum += e.power * cosine / (4.0 * M_PI * r2);
  }
  return sum;
}

}  // namespace plume
