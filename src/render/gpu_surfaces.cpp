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

// Each struct's bytes as 16-byte texels of a texel buffer (surface/texels.glsl reads them back).
template <typename T>
gpu::TexelBuffer upload(gpu::Context& ctx, const std::vector<T>& data, const char* name) {
  static_assert(sizeof(T) % 16 == 0, "a whole number of uvec4 texels");
  return gpu::TexelBuffer(ctx, data.empty() ? nullptr : data.data(), data.size() * sizeof(T) / 16,
                          VK_FORMAT_R32G32B32A32_UINT, name);
}

}  // namespace

LightTree buildLightTree(const std::vector<LightTreeEmitter>& emitters) {
  LightTree tree;
  const size_t n = emitters.size();
  if (n == 0) return tree;
  PLUME_CHECK(n < (size_t(1) << 30));
  std::vector<glm::vec3> centroid(n), normal(n);
  for (size_t i = 0; i < n; ++i) {
    const LightTreeEmitter& e = emitters[i];
    centroid[i] = (e.v0 + e.v1 + e.v2) / 3.0f;
    normal[i] = glm::normalize(glm::cross(e.v1 - e.v0, e.v2 - e.v0));
  }
  std::vector<uint32_t> order(n);
  for (size_t i = 0; i < n; ++i) order[i] = uint32_t(i);
  tree.trails.assign(n, 0u);
  tree.nodes.reserve(2 * n - 1);
  tree.nodes.emplace_back();
  struct Task {
    uint32_t node, begin, end, trail;
    int depth;
  };
  std::vector<Task> stack{{0, 0, uint32_t(n), 1u, 0}};
  while (!stack.empty()) {
    const Task t = stack.back();
    stack.pop_back();
    shared::GpuLightNode nd{};
    glm::vec3 lo(INFINITY), hi(-INFINITY), clo(INFINITY), chi(-INFINITY);
    glm::dvec3 axis(0.0);
    double power = 0.0;
    for (uint32_t k = t.begin; k < t.end; ++k) {
      const LightTreeEmitter& e = emitters[order[k]];
      lo = glm::min(lo, glm::min(e.v0, glm::min(e.v1, e.v2)));
      hi = glm::max(hi, glm::max(e.v0, glm::max(e.v1, e.v2)));
      clo = glm::min(clo, centroid[order[k]]);
      chi = glm::max(chi, centroid[order[k]]);
      axis += glm::dvec3(normal[order[k]]);
      power += e.power;
    }
    nd.boxMin = lo;
    nd.boxMax = hi;
    nd.power = float(power);
    // The cone: the normals' mean direction and the widest angle from it (a little wider, for the
    // rounding of the shader's arithmetic); no direction where the normals cancel out.
    const double len = glm::length(axis);
    nd.axis = glm::vec3(0.0f, 0.0f, 1.0f);
    nd.cosCone = -1.0f;
    if (len > 1e-6 * double(t.end - t.begin)) {
      nd.axis = glm::vec3(axis / len);
      double cosMin = 1.0;
      for (uint32_t k = t.begin; k < t.end; ++k) cosMin = std::min(cosMin, double(glm::dot(nd.axis, normal[order[k]])));
      nd.cosCone = float(std::max(-1.0, cosMin - 1e-4));
    }
    tree.depth = std::max(tree.depth, t.depth);
    if (t.end - t.begin == 1) {
      nd.child = shared::LT_LEAF | emitters[order[t.begin]].triangle;
      tree.trails[order[t.begin]] = t.trail;
      tree.nodes[t.node] = nd;
      continue;
    }
    const glm::vec3 ext = chi - clo;
    const int ax = ext.x >= ext.y && ext.x >= ext.z ? 0 : ext.y >= ext.z ? 1 : 2;
    const uint32_t mid = t.begin + (t.end - t.begin) / 2;
    std::nth_element(order.begin() + t.begin, order.begin() + mid, order.begin() + t.end,
                     [&](uint32_t a, uint32_t b) { return centroid[a][ax] < centroid[b][ax]; });
    nd.child = uint32_t(tree.nodes.size());
    tree.nodes[t.node] = nd;
    tree.nodes.emplace_back();
    tree.nodes.emplace_back();
    // The children's trails: this node's turns, the child's turn at bit `depth`, the marker above.
    const uint32_t turns = t.trail ^ (1u << t.depth);
    const uint32_t marker = 1u << (t.depth + 1);
    stack.push_back({nd.child, t.begin, mid, turns | marker, t.depth + 1});
    stack.push_back({nd.child + 1, mid, t.end, turns | (1u << t.depth) | marker, t.depth + 1});
  }
  return tree;
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
  std::vector<LightTreeEmitter> emitters;
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
      emitters.push_back({t.v0, t.v1, t.v2, p, uint32_t(i)});
      emitterVertices_.insert(emitterVertices_.end(), {t.v0, t.v1, t.v2});
      emitterTriangles_.push_back(uint32_t(i));
      emitterLuminance_.push_back((le.x + le.y + le.z) * (1.0f / 3.0f));
      t.emitterInvArea = float(1.0 / a);
    }
  }
  const LightTree lightTree = buildLightTree(emitters);
  for (size_t k = 0; k < emitters.size(); ++k) triangles[emitters[k].triangle].lightTrail = lightTree.trails[k];
  emitterCount_ = uint32_t(emitters.size());
  lightTreeDepth_ = lightTree.depth;

  bvh_ = upload(ctx, geo::bvhDeviceTexels(bvh), "BVH");
  triangles_ = upload(ctx, triangles, "surface triangles");
  materials_ = upload(ctx, materials, "surface materials");
  emitters_ = upload(ctx, lightTree.nodes, "light tree");
  uploadMs_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  logInfo(strf("surfaces: %zu triangles (%u emissive, light tree depth %d), BVH %zu nodes, %d levels, %.1f "
               "bytes/triangle on the device; built in %.0f ms",
               mesh.triangleCount(), emitterCount_, lightTreeDepth_, stats_.nodes, stats_.depth, stats_.bytesPerTriangle(),
               stats_.buildMs));
}

gpu::BindingTypes GpuSurfaces::bindingTypes(uint32_t shift) {
  gpu::BindingTypes t;
  for (uint32_t b = shared::BIND_BVH; b <= shared::BIND_EMITTERS; ++b) {
    t.push_back({b + shift, gpu::BindingType::TexelBuffer});
  }
  return t;
}

void GpuSurfaces::bind(gpu::DescriptorSet& set, uint32_t shift) const {
  set.bind(shared::BIND_BVH + shift, bvh_);
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
