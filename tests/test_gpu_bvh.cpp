// Tier c (DESIGN §7) for the surfaces' BVH: the shader traversal (shaders/surface/bvh.glsl over
// the flattened tree of geometry/bvh.cpp) against Embree's own rtcIntersect1 / rtcOccluded1 on
// the same triangles, more than 10^5 rays over a sphere, a torus, a cube and a scene of all three
// over a ground plane: random rays, rays from inside, rays aimed at vertices and at points on
// edges, rays along edges, axis-aligned rays with origins on the boxes' planes, and rays that
// miss. Closest hit: both miss, or both hit at the same distance (float tolerance below) on the
// same triangle, except exact ties: the hit point lies on an edge or vertex of Embree's triangle
// and on the shader's (a ray through a shared edge may report either neighbour), or the two
// triangles are coplanar and overlap (the scene's cube rests on the ground plane). Any hit: the
// same answer, except where Embree's own answer changes within a relative 1e-5 of tMax or tMin or the
// hit the other side missed lies on an edge or vertex; a hit the shader reports always lies on its
// triangle. Rays along an edge lie in the plane of its triangles: there Embree may report a hit
// whose point is far off its triangle; such hits are counted and not compared. Ties are counted and reported, never more than 1% of rays.
#include "geometry/bvh.h"
#include "gpu/pipeline.h"
#include "shaders/shared/rng.h"
#include "shaders/shared/sampling.h"
#include "support/gpu_fixture.h"
#include "support/meshes.h"

#include <glm/glm.hpp>

#include <chrono>
#include <cmath>
#include <functional>
#include <iomanip>
#include <limits>
#include <sstream>

using namespace plume;
namespace sh = plume::shared;

namespace {

constexpr int kRaysPerMesh = 32768;
constexpr float kInf = std::numeric_limits<float>::infinity();
// t to float tolerance: both tests compute t from coordinates of magnitude S = |origin| + t +
// the mesh's size in some tens of float operations, and a ray at angle theta to the triangle's
// plane turns an error in the plane's position into an error in t divided by |cos| of the angle
// to the normal. kTolUlps units of 2^-24 * S / |cos|.
constexpr double kTolUlps = 8.0;
// Rays of the random kinds (not aimed at edges or vertices, not along edges) pass within the
// tolerance of an edge with a probability of order 1e-6: ties among them are capped at 1e-3.
constexpr double kMaxRandomTieFraction = 1e-3;

struct RayCase {
  glm::vec4 org, dir, any;
};
struct RayResult {
  sh::BvhHit closest;
  sh::BvhHit any;
};

struct MeshCase {
  std::string name;
  geo::TriangleMesh mesh;
  std::function<glm::vec3(sh::RngState&)> inside;  // a random point inside the closed mesh
};

// Ray kinds by i % kKinds: 0-5 random, 6-8 from inside, 9-11 at a vertex, 12-14 at a point on an
// edge, 15-16 along an edge, 17 axis-aligned, 18-19 away from the mesh.
constexpr int kKinds = 20;
bool isRandomKind(int i) { return i % kKinds < 9 || i % kKinds >= 18; }

glm::vec3 rand3(sh::RngState& r) { return glm::vec3(sh::rng_float(r), sh::rng_float(r), sh::rng_float(r)); }

std::vector<MeshCase> meshCases() {
  std::vector<MeshCase> cases;
  cases.push_back({"sphere", test::makeSphere(glm::vec3(0.2f, -0.1f, 0.3f), 1.3f, 48, 96), [](sh::RngState& r) {
                     return glm::vec3(0.2f, -0.1f, 0.3f) + 1.2f * std::cbrt(sh::rng_float(r)) * sh::smp_uniform_sphere(sh::rng_float2(r));
                   }});
  cases.push_back({"torus", test::makeTorus(glm::vec3(0.0f), 1.0f, 0.35f, 96, 48), [](sh::RngState& r) {
                     const float u = 6.2831853f * sh::rng_float(r), v = 6.2831853f * sh::rng_float(r), s = 0.3f * sh::rng_float(r);
                     const float rr = 1.0f + s * std::cos(v);
                     return glm::vec3(rr * std::cos(u), s * std::sin(v), -rr * std::sin(u));
                   }});
  cases.push_back({"cube", test::makeCube(1.0f), [](sh::RngState& r) { return 1.98f * rand3(r) - glm::vec3(0.99f); }});
  geo::TriangleMesh scene = geo::makePlane(glm::vec3(0.0f, -1.5f, 0.0f), glm::vec3(0, 1, 0), glm::vec2(12.0f, 9.0f), "plane");
  geo::TriangleMesh sphere = test::makeSphere(glm::vec3(-1.8f, -0.4f, 0.0f), 0.9f, 24, 48);
  geo::TriangleMesh torus = test::makeTorus(glm::vec3(0.0f), 0.8f, 0.25f, 48, 24);
  geo::applyTransform(torus, geo::Transform::fromTrs(glm::vec3(1.5f, -0.5f, 0.2f), glm::vec3(30.0f, 0.0f, 45.0f), glm::vec3(1.0f, 1.3f, 1.0f)), "torus");
  geo::TriangleMesh cube = test::makeCube(0.5f);
  geo::applyTransform(cube, geo::Transform::fromTrs(glm::vec3(0.0f, -1.0f, 1.2f), glm::vec3(0.0f, 20.0f, 0.0f), glm::vec3(1.0f)), "cube");
  scene.append(sphere);
  scene.append(torus);
  scene.append(cube);
  cases.push_back({"scene", scene, [](sh::RngState& r) {  // inside the sphere
                     return glm::vec3(-1.8f, -0.4f, 0.0f) + 0.85f * std::cbrt(sh::rng_float(r)) * sh::smp_uniform_sphere(sh::rng_float2(r));
                   }});
  return cases;
}

std::vector<RayCase> makeRays(const MeshCase& mc, uint32_t seed) {
  const geo::TriangleMesh& m = mc.mesh;
  glm::vec3 lo(kInf), hi(-kInf);
  for (const glm::vec3& p : m.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  const glm::vec3 centre = 0.5f * (lo + hi);
  const float radius = 0.5f * glm::length(hi - lo);
  sh::RngState r = sh::rng_init(glm::uvec2(seed, 5u), 0u, sh::RNG_STREAM_TEST, 77u);
  auto vertex = [&]() { return m.positions[m.triangles[sh::rng_uint(r) % m.triangles.size()][sh::rng_uint(r) % 3u]]; };
  auto edge = [&](glm::vec3& a, glm::vec3& b) {
    const glm::uvec3 t = m.triangles[sh::rng_uint(r) % m.triangles.size()];
    const uint32_t k = sh::rng_uint(r) % 3u;
    a = m.positions[t[k]];
    b = m.positions[t[(k + 1) % 3]];
  };
  auto outside = [&]() { return centre + radius * (1.5f + 2.0f * sh::rng_float(r)) * sh::smp_uniform_sphere(sh::rng_float2(r)); };
  std::vector<RayCase> rays(kRaysPerMesh);
  for (int i = 0; i < kRaysPerMesh; ++i) {
    glm::vec3 o, d;
    const int kind = i % kKinds;
    if (kind < 6) {  // random
      o = centre + (2.0f * rand3(r) - glm::vec3(1.0f)) * (hi - lo);
      d = sh::smp_uniform_sphere(sh::rng_float2(r));
    } else if (kind < 9) {  // from inside
      o = mc.inside(r);
      d = sh::smp_uniform_sphere(sh::rng_float2(r));
    } else if (kind < 12) {  // at a vertex
      o = outside();
      d = glm::normalize(vertex() - o);
    } else if (kind < 15) {  // at a point on an edge
      glm::vec3 a, b;
      edge(a, b);
      o = outside();
      d = glm::normalize(glm::mix(a, b, sh::rng_float(r)) - o);
    } else if (kind < 17) {  // along an edge, from before it or from its middle
      glm::vec3 a, b;
      edge(a, b);
      d = glm::normalize(b - a);
      o = kind == 15 ? a - (0.05f + sh::rng_float(r)) * (b - a) : glm::mix(a, b, 0.5f);
    } else if (kind < 18) {  // axis-aligned, origin on a vertex's or the bounds' coordinates
      const int axis = int(sh::rng_uint(r) % 3u);
      const glm::vec3 v = vertex();
      o = glm::vec3(sh::rng_uint(r) % 2 ? v.x : lo.x, sh::rng_uint(r) % 2 ? v.y : hi.y, sh::rng_uint(r) % 2 ? v.z : lo.z);
      o[axis] = centre[axis] + (sh::rng_uint(r) % 2 ? 2.0f : -2.0f) * radius;
      d = glm::vec3(0.0f);
      d[axis] = o[axis] > centre[axis] ? -1.0f : 1.0f;
    } else {  // away from the bounding sphere: a miss
      o = outside();
      d = sh::smp_uniform_sphere(sh::rng_float2(r));
      if (glm::dot(d, o - centre) < 0.0f) d = -d;
    }
    const float tMax = i % 7 == 0 ? 4.0f * radius * sh::rng_float(r) : kInf;
    const float anyMax = i % 2 == 0 ? kInf : 3.0f * radius * sh::rng_float(r);
    rays[size_t(i)] = {glm::vec4(o, 0.0f), glm::vec4(d, tMax), glm::vec4(anyMax, 0, 0, 0)};
  }
  return rays;
}

double tolerance(glm::vec3 o, double t, glm::dvec3 d, glm::dvec3 normal, double size) {
  const double c = std::max(std::abs(glm::dot(d, normal)), 1e-6);
  const double s = double(std::max({std::abs(o.x), std::abs(o.y), std::abs(o.z)})) + (std::isfinite(t) ? t : 0.0) + size;
  return kTolUlps * std::ldexp(1.0, -24) * s / c;
}

glm::dvec3 vtx(const geo::TriangleMesh& m, uint32_t prim, int k) { return glm::dvec3(m.positions[m.triangles[prim][k]]); }

glm::dvec3 unitNormal(const geo::TriangleMesh& m, uint32_t prim) {
  return glm::normalize(glm::cross(vtx(m, prim, 1) - vtx(m, prim, 0), vtx(m, prim, 2) - vtx(m, prim, 0)));
}

double segmentDistance(glm::dvec3 p, glm::dvec3 a, glm::dvec3 b) {
  const double s = glm::clamp(glm::dot(p - a, b - a) / glm::dot(b - a, b - a), 0.0, 1.0);
  return glm::length(p - glm::mix(a, b, s));
}

// Distance from p to the triangle (double precision).
double triangleDistance(const geo::TriangleMesh& m, uint32_t prim, glm::dvec3 p) {
  const glm::dvec3 a = vtx(m, prim, 0), b = vtx(m, prim, 1), c = vtx(m, prim, 2), n = unitNormal(m, prim);
  const glm::dvec3 q = p - glm::dot(p - a, n) * n;  // projection onto the plane
  const bool in = glm::dot(glm::cross(b - a, q - a), n) >= 0 && glm::dot(glm::cross(c - b, q - b), n) >= 0 &&
                  glm::dot(glm::cross(a - c, q - c), n) >= 0;
  if (in) return std::abs(glm::dot(p - a, n));
  return std::min({segmentDistance(p, a, b), segmentDistance(p, b, c), segmentDistance(p, c, a)});
}

// Whether triangle b lies in triangle a's plane (its vertices within tol of it).
bool coplanar(const geo::TriangleMesh& m, uint32_t a, uint32_t b, double tol) {
  const glm::dvec3 n = unitNormal(m, a), p = vtx(m, a, 0);
  for (int k = 0; k < 3; ++k)
    if (std::abs(glm::dot(vtx(m, b, k) - p, n)) > tol) return false;
  return true;
}

double edgeDistance(const geo::TriangleMesh& m, uint32_t prim, glm::dvec3 p) {
  const glm::dvec3 a = vtx(m, prim, 0), b = vtx(m, prim, 1), c = vtx(m, prim, 2);
  return std::min({segmentDistance(p, a, b), segmentDistance(p, b, c), segmentDistance(p, c, a)});
}

struct Tally {
  int rays = 0, hits = 0, closestMismatch = 0, anyMismatch = 0, baryMismatch = 0;
  int primTies = 0, edgeTies = 0, anyTies = 0, coplanarTies = 0;  // see the file's comment
  int embreeSpurious = 0;  // Embree hits off their triangle, rays along edges
  int randomTies = 0;                          // ties among rays not aimed at edges or vertices
  double worstTRatio = 0.0;  // |dt| / tolerance over rays with the same triangle
  std::ostringstream log;
};

class GpuBvh : public test::GpuTest {
 protected:
  double traceMs = 0.0;  // the last trace's submit-to-finish time (closest + any hit per ray)
  int stackSlack = 0;    // traversal stack entries beyond the tree's depth (ShortStackFails: < 0)
  std::vector<RayResult> trace(const geo::FlatBvh& bvh, const std::vector<RayCase>& rays) {
    using gpu::BindingType;
    // The stack as the renderer compiles it: the tree's own depth (render/features.h bvhStack).
    const gpu::ShaderDefines stack{{"PLUME_BVH_STACK", std::to_string(bvh.stats.depth + stackSlack)}};
    gpu::ComputePass pass(ctx(), compiler().compile("tests/bvh_kernels.comp", stack),
                          {BindingType::TexelBuffer, BindingType::StorageBuffer, BindingType::StorageBuffer},
                          4, "bvh kernels", glm::uvec3(64, 1, 1));
    const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    // As render/gpu_surfaces.cpp uploads it: one texel buffer (shared/bvh.h, "On the device").
    const std::vector<glm::uvec4> texels = geo::bvhDeviceTexels(bvh);
    gpu::TexelBuffer tree(ctx(), texels.data(), texels.size(), VK_FORMAT_R32G32B32A32_UINT, "bvh");
    gpu::Buffer in(ctx(), rays.size() * sizeof(RayCase), storage, "rays");
    gpu::Buffer out(ctx(), rays.size() * sizeof(RayResult), storage, "results");
    in.upload(rays.data(), rays.size() * sizeof(RayCase));
    pass.set.bind(0, tree);
    pass.set.bind(1, in);
    pass.set.bind(2, out);
    const uint32_t count = uint32_t(rays.size());
    const auto t0 = std::chrono::steady_clock::now();
    ctx().submitAndWait([&](VkCommandBuffer cmd) { pass.record(cmd, glm::uvec3(count, 1, 1), &count); });
    traceMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    std::vector<RayResult> results(rays.size());
    out.download(results.data(), results.size() * sizeof(RayResult));
    return results;
  }
};

void compare(const MeshCase& mc, const geo::EmbreeScene& embree, const std::vector<RayCase>& rays,
             const std::vector<RayResult>& gpu, Tally& tally) {
  const geo::TriangleMesh& m = mc.mesh;
  glm::vec3 lo(kInf), hi(-kInf);
  for (const glm::vec3& p : m.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  const double size = glm::length(hi - lo);
  auto note = [&](const char* what, size_t i, const sh::BvhHit& e, const sh::BvhHit& g) {
    if (tally.log.tellp() > 4000) return;
    const RayCase& c = rays[i];
    tally.log << std::setprecision(9) << mc.name << " ray " << i << " (" << what << "): o " << c.org.x << " " << c.org.y << " " << c.org.z << " d " << c.dir.x << " "
              << c.dir.y << " " << c.dir.z << " tMax " << c.dir.w << " any tMax " << c.any.x << " | embree t " << e.t << " prim " << e.prim << " | shader t " << g.t
              << " prim " << g.prim;
    // The true closest hit by brute force in double precision (Möller-Trumbore), for diagnosis.
    double best = 1e300; int bp = -1;
    for (size_t k = 0; k < m.triangles.size(); ++k) {
      glm::dvec3 a = vtx(m, uint32_t(k), 0), b = vtx(m, uint32_t(k), 1), cc = vtx(m, uint32_t(k), 2);
      glm::dvec3 D(c.dir), O(c.org), e1 = b - a, e2 = cc - a, pv = glm::cross(D, e2);
      double det = glm::dot(e1, pv); if (det == 0) continue;
      glm::dvec3 tv = O - a; double u = glm::dot(tv, pv) / det; if (u < 0 || u > 1) continue;
      glm::dvec3 qv = glm::cross(tv, e1); double v = glm::dot(D, qv) / det; if (v < 0 || u + v > 1) continue;
      double t = glm::dot(e2, qv) / det; if (t > 0 && t < best) { best = t; bp = int(k); }
    }
    tally.log << " | brute t " << best << " prim " << bp << "\n";
  };
  for (size_t i = 0; i < rays.size(); ++i) {
    const glm::vec3 o(rays[i].org), d(rays[i].dir);
    const glm::dvec3 dd(d);
    const sh::BvhHit e = embree.intersect(o, d, rays[i].org.w, rays[i].dir.w);
    const sh::BvhHit& g = gpu[i].closest;
    const bool random = isRandomKind(int(i));
    ++tally.rays;
    auto point = [&](const sh::BvhHit& h) { return glm::dvec3(o) + double(h.t) * dd; };
    auto tol = [&](const sh::BvhHit& h) { return tolerance(o, h.t, dd, unitNormal(m, h.prim), size); };
    auto onEdge = [&](const sh::BvhHit& h) { return edgeDistance(m, h.prim, point(h)) <= tol(h); };
    // Embree's robust test reports, for a ray running along an edge in its triangles' plane, hits
    // far off the triangle (t from a determinant of ~0): counted, allowed for those rays only.
    const bool alongEdge = i % kKinds == 15 || i % kKinds == 16;
    auto spurious = [&](const sh::BvhHit& h) { return h.prim != sh::BVH_NONE && triangleDistance(m, h.prim, point(h)) > tol(h); };
    if (e.prim == sh::BVH_NONE && g.prim == sh::BVH_NONE) {
      // both miss
    } else if (g.prim != sh::BVH_NONE && triangleDistance(m, g.prim, point(g)) > tol(g)) {
      ++tally.closestMismatch;  // the shader's hit point is not on its triangle
      note("not on the triangle", i, e, g);
    } else if (e.prim != sh::BVH_NONE && g.prim != sh::BVH_NONE && std::abs(double(g.t) - double(e.t)) <= tol(e)) {
      ++tally.hits;
      if (g.prim == e.prim) {
        tally.worstTRatio = std::max(tally.worstTRatio, std::abs(double(g.t) - double(e.t)) / tol(e));
        // The shader's barycentrics name its hit point.
        const glm::dvec3 q = (1.0 - g.u - g.v) * vtx(m, g.prim, 0) + double(g.u) * vtx(m, g.prim, 1) + double(g.v) * vtx(m, g.prim, 2);
        if (glm::length(q - point(g)) > tol(g)) {
          ++tally.baryMismatch;
          note("barycentrics", i, e, g);
        }
      } else if (onEdge(e) || onEdge(g)) {  // a shared edge or vertex, or an edge on the other's face (checked above: the shader's point is on its triangle)
        ++tally.primTies;
        tally.randomTies += random;
      } else if (coplanar(m, e.prim, g.prim, tol(e))) {  // coincident surfaces (a cube resting on the ground)
        ++tally.coplanarTies;
      } else {
        ++tally.closestMismatch;
        note("triangle", i, e, g);
      }
    } else {
      // Different distances, or one hit and one miss: a tie only when the nearer hit lies on an
      // edge or vertex of its triangle (the other test's rounding let the ray slip through there).
      tally.hits += e.prim != sh::BVH_NONE && g.prim != sh::BVH_NONE;
      const sh::BvhHit& nearer = g.prim == sh::BVH_NONE || (e.prim != sh::BVH_NONE && e.t < g.t) ? e : g;
      if (alongEdge && spurious(e)) {
        ++tally.embreeSpurious;
      } else if (onEdge(nearer)) {
        ++tally.edgeTies;
        tally.randomTies += random;
      } else {
        ++tally.closestMismatch;
        note(e.prim == sh::BVH_NONE || g.prim == sh::BVH_NONE ? "hit/miss" : "distance", i, e, g);
      }
    }
    const float anyMax = rays[i].any.x;
    const sh::BvhHit& ga = gpu[i].any;
    const bool eAny = embree.occluded(o, d, rays[i].org.w, anyMax);
    if (ga.prim != sh::BVH_NONE && !(ga.t < anyMax && triangleDistance(m, ga.prim, point(ga)) <= tol(ga))) {
      ++tally.anyMismatch;  // not a hit of its triangle within the range
      note("any hit not on its triangle", i, e, ga);
    } else if (eAny != (ga.prim != sh::BVH_NONE)) {
      // A tie when Embree's answer changes within a relative 1e-5 of tMax, or when the hit the
      // other side missed lies on an edge or vertex of its triangle.
      const float tMin = rays[i].org.w;
      const bool boundary = embree.occluded(o, d, tMin, anyMax * (1.0f - 1e-5f)) != embree.occluded(o, d, tMin, anyMax * (1.0f + 1e-5f)) ||
                            embree.occluded(o, d, tMin + 1e-5f * float(size), anyMax) != eAny;
      const sh::BvhHit hit = eAny ? embree.intersect(o, d, rays[i].org.w, anyMax) : ga;
      if (alongEdge && eAny && spurious(hit)) {
        ++tally.embreeSpurious;
      } else if (boundary || (hit.prim != sh::BVH_NONE && onEdge(hit))) {
        ++tally.anyTies;
        tally.randomTies += random;
      } else {
        ++tally.anyMismatch;
        note(eAny ? "any hit: embree occluded, shader not" : "any hit: shader occluded, embree not", i, e, ga);
      }
    }
  }
}

}  // namespace

TEST_F(GpuBvh, ShaderTraversalEqualsEmbree) {
  int total = 0;
  uint32_t seed = 1;
  for (const MeshCase& mc : meshCases()) {
    for (bool splits : {true, false}) {
      if (!splits && mc.name != "scene") continue;  // the binned build without spatial splits, once
      geo::BvhOptions options;
      options.spatialSplits = splits;
      const geo::FlatBvh bvh = geo::buildBvh(mc.mesh, options);
      const geo::EmbreeScene embree(mc.mesh);
      const std::vector<RayCase> rays = makeRays(mc, seed++);
      const std::vector<RayResult> gpu = trace(bvh, rays);
      Tally tally;
      compare(mc, embree, rays, gpu, tally);
      total += tally.rays;
      std::printf("[ bvh ] %-6s%s %6zu triangles: build %.2f ms (+ flatten %.2f ms), %zu nodes, %zu references, depth %d, "
                  "%.1f bytes/triangle on the device | %d rays, %d hits, ties: %d triangle, %d edge, %d any, %d coplanar "
                  "(%d among random rays); %d spurious Embree hits; worst |dt|/tol %.3f; traced in %.1f ms\n",
                  mc.name.c_str(), splits ? "" : " (no splits)", bvh.stats.inputTriangles, bvh.stats.buildMs, bvh.stats.flattenMs,
                  bvh.stats.nodes, bvh.stats.references, bvh.stats.depth, bvh.stats.bytesPerTriangle(), tally.rays, tally.hits,
                  tally.primTies, tally.edgeTies, tally.anyTies, tally.coplanarTies, tally.randomTies, tally.embreeSpurious,
                  tally.worstTRatio, traceMs);
      EXPECT_EQ(tally.closestMismatch, 0) << mc.name << "\n" << tally.log.str();
      EXPECT_EQ(tally.baryMismatch, 0) << mc.name << "\n" << tally.log.str();
      EXPECT_EQ(tally.anyMismatch, 0) << mc.name << "\n" << tally.log.str();
      EXPECT_LE(tally.randomTies, kMaxRandomTieFraction * tally.rays) << mc.name;
      EXPECT_LE(tally.embreeSpurious, kMaxRandomTieFraction * tally.rays) << mc.name;
      EXPECT_GT(tally.hits, tally.rays / 4) << mc.name << ": the rays must mostly hit";
    }
  }
  EXPECT_GE(total, 100000);
}

// The comparison catches a broken tree: every leaf's box shrunk by 10% about its centre (triangles
// poke out of their boxes) must give mismatches.
TEST_F(GpuBvh, ComparisonCanFail) {
  const MeshCase mc = meshCases()[0];
  geo::FlatBvh bvh = geo::buildBvh(mc.mesh);
  auto shrink = [](glm::vec3& lo, glm::vec3& hi) {
    const glm::vec3 c = 0.5f * (lo + hi), h = 0.45f * (hi - lo);
    lo = c - h, hi = c + h;
  };
  for (sh::BvhNode& n : bvh.nodes) {
    if (n.count0 > 0) shrink(n.lo0, n.hi0);
    if (n.count1 > 0) shrink(n.lo1, n.hi1);
  }
  const geo::EmbreeScene embree(mc.mesh);
  const std::vector<RayCase> rays = makeRays(mc, 99);
  Tally tally;
  compare(mc, embree, rays, trace(bvh, rays), tally);
  EXPECT_GT(tally.closestMismatch, 0);
  EXPECT_GT(tally.anyMismatch, 0);
}

// The traversal keeps far children in a stack of the tree's depth (render/features.h bvhStack:
// at most one waits per inner node on the path to the current item). The comparison sees lost
// entries: on the cube (depth 5) a stack of 2 drops far children that many rays need. (Random
// rays rarely fill the stack: none of 32768 per mesh lost a hit at depth - 3 on the other meshes.)
TEST_F(GpuBvh, ShortStackFails) {
  const MeshCase mc = meshCases()[2];
  ASSERT_EQ(mc.name, "cube");
  const geo::FlatBvh bvh = geo::buildBvh(mc.mesh);
  ASSERT_EQ(bvh.stats.depth, 5);
  const geo::EmbreeScene embree(mc.mesh);
  const std::vector<RayCase> rays = makeRays(mc, 7);
  stackSlack = 2 - bvh.stats.depth;
  Tally tally;
  compare(mc, embree, rays, trace(bvh, rays), tally);
  EXPECT_GT(tally.closestMismatch, 100);
  stackSlack = 0;
  Tally exact;
  compare(mc, embree, rays, trace(bvh, rays), exact);
  EXPECT_EQ(exact.closestMismatch, 0);
}
