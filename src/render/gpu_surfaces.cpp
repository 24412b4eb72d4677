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

// ceil(log2(n)): the depth of a median-split tree over n leaves.
int depthLeft(size_t n) {
  int d = 0;
  while ((size_t(1) << d) < n) ++d;
  return d;
}

// pbrt-v4's orientation measure of a node (BVHLightSampler::EvaluateCost): the solid angle,
// cosine-weighted, into which emitters whose front normals lie within theta_o of an axis can send
// light, each over a hemisphere (theta_e = 90 degrees: one-sided emitters).
double orientationMeasure(double cosO) {
  const double thetaO = std::acos(std::clamp(cosO, -1.0, 1.0));
  const double thetaW = std::min(thetaO + 0.5 * M_PI, M_PI);
  const double sinO = std::sqrt(std::max(0.0, 1.0 - cosO * cosO));
  return 2.0 * M_PI * (1.0 - cosO) +
         0.5 * M_PI * (2.0 * thetaW * sinO - std::cos(thetaO - 2.0 * thetaW) - 2.0 * thetaO * sinO + cosO);
}

// What the surface area orientation heuristic (SAOH) needs of a set of emitters: their triangles'
// box, summed power and normals, and their count (a bucket's cone is kept beside it, for
// unionCone, so that a split's cone needs no other pass over the emitters).
struct SplitBounds {
  glm::dvec3 lo{INFINITY}, hi{-INFINITY};
  glm::dvec3 normalSum{0.0};
  double power = 0.0;
  size_t count = 0;
  void add(const SplitBounds& o) {
    lo = glm::min(lo, o.lo);
    hi = glm::max(hi, o.hi);
    normalSum += o.normalSum;
    power += o.power;
    count += o.count;
  }
  double area() const {
    if (count == 0) return 0.0;
    const glm::dvec3 d = hi - lo;
    return 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
  }
};

// The cosine of the half-angle of a cone around `axis` that holds every bucket's cone
// (axis[k], cosine[k]) in [first, last); -1 where the normals cancel out.
double unionCone(const glm::dvec3& normalSum, const std::vector<glm::dvec3>& axes, const std::vector<double>& cosines,
                 int first, int last, const std::vector<SplitBounds>& buckets) {
  const double len = glm::length(normalSum);
  if (!(len > 1e-9)) return -1.0;
  const glm::dvec3 axis = normalSum / len;
  double angle = 0.0;
  for (int k = first; k < last; ++k) {
    if (buckets[size_t(k)].count == 0) continue;
    angle = std::max(angle, std::acos(std::clamp(glm::dot(axis, axes[size_t(k)]), -1.0, 1.0)) +
                                std::acos(std::clamp(cosines[size_t(k)], -1.0, 1.0)));
  }
  return angle >= M_PI ? -1.0 : std::cos(angle);
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
    // The split: the plane of least SAOH cost among 12 buckets of the centroids along each axis
    // (Conty Estevez and Kulla 2018; pbrt-v4's BVHLightSampler): the children's power x
    // orientation measure x box area, so that emitters facing apart (the windows of opposite
    // facades, lamps facing down beside them) part early and the cones below stay narrow. The
    // median on the longest axis where no plane separates the centroids, or where the split would
    // leave a child too large for the trails' 32 bits (depth + 1 + ceil(log2 of its size) <= 30
    // keeps every leaf within them).
    uint32_t mid = 0;
    {
      constexpr int kBuckets = 12;
      double bestCost = INFINITY;
      int bestAxis = -1, bestSplit = 0;
      std::vector<SplitBounds> buckets(kBuckets);
      std::vector<glm::dvec3> axes(kBuckets);
      std::vector<double> cosines(kBuckets);
      auto bucketOf = [&](uint32_t e, int a) {
        const double f = (double(centroid[e][a]) - double(clo[a])) / double(ext[a]);
        return std::clamp(int(f * kBuckets), 0, kBuckets - 1);
      };
      for (int a = 0; a < 3; ++a) {
        if (!(ext[a] > 0.0f)) continue;
        std::fill(buckets.begin(), buckets.end(), SplitBounds{});
        for (uint32_t k = t.begin; k < t.end; ++k) {
          const LightTreeEmitter& e = emitters[order[k]];
          SplitBounds& b = buckets[size_t(bucketOf(order[k], a))];
          b.lo = glm::min(b.lo, glm::dvec3(glm::min(e.v0, glm::min(e.v1, e.v2))));
          b.hi = glm::max(b.hi, glm::dvec3(glm::max(e.v0, glm::max(e.v1, e.v2))));
          b.normalSum += glm::dvec3(normal[order[k]]);
          b.power += e.power;
          ++b.count;
        }
        for (int k = 0; k < kBuckets; ++k) {
          const double len = glm::length(buckets[size_t(k)].normalSum);
          axes[size_t(k)] = len > 1e-9 ? buckets[size_t(k)].normalSum / len : glm::dvec3(0.0, 0.0, 1.0);
          cosines[size_t(k)] = len > 1e-9 ? 1.0 : -1.0;
        }
        for (uint32_t k = t.begin; k < t.end; ++k) {
          const size_t b = size_t(bucketOf(order[k], a));
          if (cosines[b] > -1.0) cosines[b] = std::min(cosines[b], glm::dot(axes[b], glm::dvec3(normal[order[k]])));
        }
        const double kr = double(std::max(ext.x, std::max(ext.y, ext.z))) / double(ext[a]);
        for (int split = 1; split < kBuckets; ++split) {
          SplitBounds left, right;
          for (int k = 0; k < split; ++k) left.add(buckets[size_t(k)]);
          for (int k = split; k < kBuckets; ++k) right.add(buckets[size_t(k)]);
          if (left.count == 0 || right.count == 0) continue;
          const int rest = depthLeft(std::max(left.count, right.count));
          if (t.depth + 1 + rest > 30) continue;
          const double cost = kr * (left.power * orientationMeasure(unionCone(left.normalSum, axes, cosines, 0, split, buckets)) * left.area() +
                                    right.power * orientationMeasure(unionCone(right.normalSum, axes, cosines, split, kBuckets, buckets)) * right.area());
          if (cost < bestCost) {
            bestCost = cost;
            bestAxis = a;
            bestSplit = split;
          }
        }
      }
      if (bestAxis >= 0) {
        mid = uint32_t(std::partition(order.begin() + t.begin, order.begin() + t.end,
                                      [&](uint32_t e) { return bucketOf(e, bestAxis) < bestSplit; }) -
                       order.begin());
      } else {
        mid = t.begin + (t.end - t.begin) / 2;
        std::nth_element(order.begin() + t.begin, order.begin() + mid, order.begin() + t.end,
                         [&](uint32_t a, uint32_t b) { return centroid[a][ax] < centroid[b][ax]; });
      }
    }
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
