// Why rtcBuildBVH rather than an Embree scene: Embree's own BVH nodes are not public API (Embree 3
// has no supported way to read them), while the builder API hands every node and leaf to our
// callbacks, so the layout of shaders/shared/bvh.h is ours and the build is still Embree's
// (binned SAH, spatial splits, parallel). The callbacks build a pointer tree in Embree's
// thread-local memory; one depth-first pass then flattens it (children after their parent).
#include "geometry/bvh.h"

#include "core/error.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <string>
#include <utility>

namespace plume::geo {
namespace sh = plume::shared;
namespace {

// One Embree device for the process, made on first use (a scene without surfaces makes none).
// Errors reported through the callback are kept per thread and turned into exceptions.
thread_local std::string tlsEmbreeError;
thread_local RTCError tlsEmbreeCode = RTC_ERROR_NONE;

void onEmbreeError(void*, RTCError code, const char* message) {
  if (tlsEmbreeCode == RTC_ERROR_NONE) {
    tlsEmbreeCode = code;
    tlsEmbreeError = message ? message : "";
  }
}

RTCDevice device() {
  static std::once_flag once;
  static RTCDevice dev = nullptr;
  std::call_once(once, [] {
    dev = rtcNewDevice(nullptr);
    if (!dev) throw InternalError("Embree: rtcNewDevice failed (error " + std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    rtcSetDeviceErrorFunction(dev, onEmbreeError, nullptr);
  });
  return dev;
}

void throwOnEmbreeError(const char* what) {
  const RTCError code = tlsEmbreeCode;
  const std::string message = tlsEmbreeError;
  tlsEmbreeCode = RTC_ERROR_NONE;
  tlsEmbreeError.clear();
  if (code == RTC_ERROR_NONE) return;
  const std::string text = std::string("Embree: ") + what + ": " + message + " (error " + std::to_string(int(code)) + ")";
  if (code == RTC_ERROR_OUT_OF_MEMORY) throw DeviceError(text);
  throw InternalError(text);
}

enum class Kind : uint32_t { Inner, Leaf };
Kind kindOf(const void* node) { return *static_cast<const Kind*>(node); }
struct TreeInner {
  Kind kind;
  RTCBounds bounds[2];
  const void* child[2];
};
struct TreeLeaf {
  Kind kind;
  uint32_t count;
  uint32_t prim[sh::BVH_MAX_LEAF_SIZE];
};

struct BuildInput {
  const TriangleMesh* mesh;
};

void* createNode(RTCThreadLocalAllocator alloc, unsigned int childCount, void*) {
  PLUME_CHECK(childCount == 2);
  auto* node = static_cast<TreeInner*>(rtcThreadLocalAlloc(alloc, sizeof(TreeInner), 16));
  node->kind = Kind::Inner;
  return node;
}

void setNodeChildren(void* node, void** children, unsigned int count, void*) {
  for (unsigned i = 0; i < count; ++i) static_cast<TreeInner*>(node)->child[i] = children[i];
}

void setNodeBounds(void* node, const RTCBounds** bounds, unsigned int count, void*) {
  for (unsigned i = 0; i < count; ++i) static_cast<TreeInner*>(node)->bounds[i] = *bounds[i];
}

void* createLeaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive* prims, size_t count, void*) {
  PLUME_CHECK(count >= 1 && count <= sh::BVH_MAX_LEAF_SIZE);
  auto* leaf = static_cast<TreeLeaf*>(rtcThreadLocalAlloc(alloc, sizeof(TreeLeaf), 16));
  leaf->kind = Kind::Leaf;
  leaf->count = uint32_t(count);
  for (size_t i = 0; i < count; ++i) leaf->prim[i] = prims[i].primID;
  return leaf;
}

// Float bounds that contain a double value: rounded down for a lower, up for an upper bound.
float roundDown(double x) {
  float f = float(x);
  return double(f) > x ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}
float roundUp(double x) {
  float f = float(x);
  return double(f) < x ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

struct Box {
  glm::dvec3 lo{std::numeric_limits<double>::infinity()}, hi{-std::numeric_limits<double>::infinity()};
  void extend(glm::dvec3 p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
};

// Bounds of the parts of a triangle on either side of the plane x[dim] = pos, clipped to the
// bounds the reference already has (it may be a piece of an earlier split). Crossing points are
// computed in double and the boxes rounded outwards, so each box contains its part exactly.
void splitPrimitive(const RTCBuildPrimitive* prim, unsigned int dim, float pos, RTCBounds* left, RTCBounds* right,
                    void* user) {
  const TriangleMesh& mesh = *static_cast<const BuildInput*>(user)->mesh;
  const glm::uvec3 t = mesh.triangles[prim->primID];
  const glm::dvec3 v[3] = {glm::dvec3(mesh.positions[t.x]), glm::dvec3(mesh.positions[t.y]), glm::dvec3(mesh.positions[t.z])};
  Box l, r;
  for (int i = 0; i < 3; ++i) {
    const glm::dvec3 a = v[i], b = v[(i + 1) % 3];
    if (a[dim] <= pos) l.extend(a);
    if (a[dim] >= pos) r.extend(a);
    if ((a[dim] < pos && b[dim] > pos) || (a[dim] > pos && b[dim] < pos)) {
      glm::dvec3 p = glm::mix(a, b, (double(pos) - a[dim]) / (b[dim] - a[dim]));
      p[dim] = pos;
      l.extend(p);
      r.extend(p);
    }
  }
  const float plo[3] = {prim->lower_x, prim->lower_y, prim->lower_z};
  const float phi[3] = {prim->upper_x, prim->upper_y, prim->upper_z};
  auto store = [&](const Box& b, RTCBounds* out, bool isLeft) {
    float lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::max(roundDown(b.lo[a]), plo[a]);
      hi[a] = std::min(roundUp(b.hi[a]), phi[a]);
    }
    if (isLeft) hi[dim] = std::min(hi[dim], pos);
    else lo[dim] = std::max(lo[dim], pos);
    out->lower_x = lo[0], out->lower_y = lo[1], out->lower_z = lo[2];
    out->upper_x = hi[0], out->upper_y = hi[1], out->upper_z = hi[2];
  };
  store(l, left, true);
  store(r, right, false);
}

void setChild(sh::BvhNode& node, int c, const RTCBounds& b, uint32_t ref, uint32_t count) {
  const glm::vec3 lo(b.lower_x, b.lower_y, b.lower_z), hi(b.upper_x, b.upper_y, b.upper_z);
  if (c == 0) {
    node.lo0 = lo, node.hi0 = hi, node.ref0 = ref, node.count0 = count;
  } else {
    node.lo1 = lo, node.hi1 = hi, node.ref1 = ref, node.count1 = count;
  }
}

void emptyChild(sh::BvhNode& node, int c) {
  RTCBounds none{};
  setChild(node, c, none, sh::BVH_NONE, 0u);
}

void appendLeaf(FlatBvh& out, const TriangleMesh& mesh, const TreeLeaf& leaf) {
  for (uint32_t i = 0; i < leaf.count; ++i) {
    const glm::uvec3 t = mesh.triangles[leaf.prim[i]];
    sh::BvhTriangle tri{};
    tri.v0 = mesh.positions[t.x];
    tri.v1 = mesh.positions[t.y];
    tri.v2 = mesh.positions[t.z];
    tri.prim = leaf.prim[i];
    out.triangles.push_back(tri);
  }
  ++out.stats.leaves;
}

// Depth-first, each inner node's children placed after it.
void flatten(FlatBvh& out, const TriangleMesh& mesh, const void* root, const RTCBounds& rootBounds) {
  out.nodes.push_back(sh::BvhNode{});
  if (!root) {  // no triangle
    emptyChild(out.nodes[0], 0);
    emptyChild(out.nodes[0], 1);
    return;
  }
  if (kindOf(root) == Kind::Leaf) {  // one leaf: a root with one child
    const uint32_t first = uint32_t(out.triangles.size());
    appendLeaf(out, mesh, *static_cast<const TreeLeaf*>(root));
    setChild(out.nodes[0], 0, rootBounds, first, uint32_t(out.triangles.size()) - first);
    emptyChild(out.nodes[0], 1);
    out.stats.depth = 1;
    return;
  }
  struct Item {
    const TreeInner* node;
    uint32_t index;
    int depth;
  };
  std::vector<Item> stack{{static_cast<const TreeInner*>(root), 0u, 1}};
  while (!stack.empty()) {
    const Item item = stack.back();
    stack.pop_back();
    out.stats.depth = std::max(out.stats.depth, item.depth);
    for (int c = 0; c < 2; ++c) {
      const void* child = item.node->child[c];
      if (kindOf(child) == Kind::Leaf) {
        const uint32_t first = uint32_t(out.triangles.size());
        appendLeaf(out, mesh, *static_cast<const TreeLeaf*>(child));
        setChild(out.nodes[item.index], c, item.node->bounds[c], first, uint32_t(out.triangles.size()) - first);
      } else {
        const uint32_t index = uint32_t(out.nodes.size());
        out.nodes.push_back(sh::BvhNode{});
        setChild(out.nodes[item.index], c, item.node->bounds[c], index, 0u);
        stack.push_back({static_cast<const TreeInner*>(child), index, item.depth + 1});
      }
    }
  }
}

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

std::vector<glm::uvec4> bvhDeviceTexels(const FlatBvh& bvh) {
  static_assert(sizeof(shared::BvhNode) == 16 * shared::BVH_NODE_TEXEL_COUNT, "BvhNode: 4 texels");
  static_assert(sizeof(shared::BvhTriangle) == 16 * shared::BVH_TRIANGLE_TEXEL_COUNT, "BvhTriangle: 3 texels");
  const size_t first = shared::BVH_HEADER_TEXELS + bvh.nodes.size() * shared::BVH_NODE_TEXEL_COUNT;
  std::vector<glm::uvec4> texels(first + bvh.triangles.size() * shared::BVH_TRIANGLE_TEXEL_COUNT + 1, glm::uvec4(0u));
  texels[0].x = uint32_t(first);
  if (!bvh.nodes.empty()) std::memcpy(&texels[shared::BVH_HEADER_TEXELS], bvh.nodes.data(), bvh.nodes.size() * sizeof(shared::BvhNode));
  if (!bvh.triangles.empty()) std::memcpy(&texels[first], bvh.triangles.data(), bvh.triangles.size() * sizeof(shared::BvhTriangle));
  return texels;
}

FlatBvh buildBvh(const TriangleMesh& mesh, const BvhOptions& options) {
  FlatBvh out;
  out.stats.inputTriangles = mesh.triangles.size();
  const auto t0 = std::chrono::steady_clock::now();
  const size_t n = mesh.triangles.size();
  // With spatial splits the builder appends the split references after the input: room for 2x.
  const size_t capacity = options.spatialSplits ? 2 * n : n;
  std::vector<RTCBuildPrimitive> prims(capacity);
  RTCBounds rootBounds{};
  rootBounds.lower_x = rootBounds.lower_y = rootBounds.lower_z = std::numeric_limits<float>::infinity();
  rootBounds.upper_x = rootBounds.upper_y = rootBounds.upper_z = -std::numeric_limits<float>::infinity();
  for (size_t i = 0; i < n; ++i) {
    const glm::uvec3 t = mesh.triangles[i];
    const glm::vec3 a = mesh.positions[t.x], b = mesh.positions[t.y], c = mesh.positions[t.z];
    const glm::vec3 lo = glm::min(a, glm::min(b, c)), hi = glm::max(a, glm::max(b, c));
    RTCBuildPrimitive& p = prims[i];
    p.lower_x = lo.x, p.lower_y = lo.y, p.lower_z = lo.z, p.geomID = 0;
    p.upper_x = hi.x, p.upper_y = hi.y, p.upper_z = hi.z, p.primID = uint32_t(i);
    rootBounds.lower_x = std::min(rootBounds.lower_x, lo.x), rootBounds.upper_x = std::max(rootBounds.upper_x, hi.x);
    rootBounds.lower_y = std::min(rootBounds.lower_y, lo.y), rootBounds.upper_y = std::max(rootBounds.upper_y, hi.y);
    rootBounds.lower_z = std::min(rootBounds.lower_z, lo.z), rootBounds.upper_z = std::max(rootBounds.upper_z, hi.z);
  }
  RTCBVH bvh = nullptr;
  const void* root = nullptr;
  if (n > 0) {
    bvh = rtcNewBVH(device());
    throwOnEmbreeError("rtcNewBVH");
    BuildInput input{&mesh};
    RTCBuildArguments args = rtcDefaultBuildArguments();
    args.buildQuality = RTC_BUILD_QUALITY_HIGH;
    args.maxBranchingFactor = 2;
    args.maxDepth = sh::BVH_MAX_DEPTH;
    args.minLeafSize = 1;
    args.maxLeafSize = sh::BVH_MAX_LEAF_SIZE;
    args.traversalCost = 1.0f;
    args.intersectionCost = 1.0f;
    args.bvh = bvh;
    args.primitives = prims.data();
    args.primitiveCount = n;
    args.primitiveArrayCapacity = capacity;
    args.createNode = createNode;
    args.setNodeChildren = setNodeChildren;
    args.setNodeBounds = setNodeBounds;
    args.createLeaf = createLeaf;
    args.splitPrimitive = options.spatialSplits ? splitPrimitive : nullptr;
    args.userPtr = &input;
    root = rtcBuildBVH(&args);
    try {
      throwOnEmbreeError("rtcBuildBVH");
    } catch (...) {
      rtcReleaseBVH(bvh);
      throw;
    }
  }
  out.stats.buildMs = msSince(t0);
  const auto t1 = std::chrono::steady_clock::now();
  out.nodes.reserve(n / 2 + 1);
  out.triangles.reserve(n + n / 8);
  flatten(out, mesh, root, rootBounds);
  out.stats.flattenMs = msSince(t1);
  const auto t2 = std::chrono::steady_clock::now();
  if (bvh) rtcReleaseBVH(bvh);  // Embree's nodes: part of the build's cost
  out.stats.buildMs += msSince(t2);
  out.stats.nodes = out.nodes.size();
  out.stats.references = out.triangles.size();
  out.stats.bytes = 16 * (sh::BVH_HEADER_TEXELS + 1) + out.nodes.size() * sizeof(sh::BvhNode) +
                    out.triangles.size() * sizeof(sh::BvhTriangle);  // bvhDeviceTexels
  // The traversal packs a child reference with its count in one word (ref << 3 | count).
  if (out.triangles.size() >= (size_t(1) << 29) || out.nodes.size() >= (size_t(1) << 29))
    throw InputError("the surfaces hold " + std::to_string(out.triangles.size()) + " triangle references, more than the 2^29 the BVH layout addresses");
  if (out.stats.depth > sh::BVH_STACK_SIZE)
    throw InputError("the surfaces' BVH is " + std::to_string(out.stats.depth) + " levels deep, more than the " +
                     std::to_string(sh::BVH_STACK_SIZE) + " the shaders' traversal stack holds");
  return out;
}

// --- The Embree scene ----------------------------------------------------------------------------

struct EmbreeScene::Impl {
  RTCScene scene = nullptr;
};

namespace {
std::atomic<size_t> embreeScenesBuilt{0};
}  // namespace

size_t EmbreeScene::built() { return embreeScenesBuilt.load(); }

EmbreeScene::EmbreeScene(const TriangleMesh& mesh) : impl_(std::make_unique<Impl>()) {
  ++embreeScenesBuilt;
  RTCDevice dev = device();
  impl_->scene = rtcNewScene(dev);
  rtcSetSceneFlags(impl_->scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
  if (mesh.triangles.empty()) {  // an empty scene: every ray misses
    rtcCommitScene(impl_->scene);
    throwOnEmbreeError("rtcCommitScene");
    return;
  }
  RTCGeometry geom = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                         3 * sizeof(float), std::max<size_t>(mesh.positions.size(), 1)));
  auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                              3 * sizeof(uint32_t), mesh.triangles.size()));
  throwOnEmbreeError("rtcSetNewGeometryBuffer");
  for (size_t i = 0; i < mesh.positions.size(); ++i)
    for (int a = 0; a < 3; ++a) v[3 * i + size_t(a)] = mesh.positions[i][a];
  for (size_t i = 0; i < mesh.triangles.size(); ++i)
    for (int a = 0; a < 3; ++a) idx[3 * i + size_t(a)] = mesh.triangles[i][a];
  rtcSetGeometryBuildQuality(geom, RTC_BUILD_QUALITY_HIGH);
  rtcCommitGeometry(geom);
  rtcAttachGeometry(impl_->scene, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(impl_->scene);
  throwOnEmbreeError("rtcCommitScene");
}

EmbreeScene::~EmbreeScene() {
  if (impl_ && impl_->scene) rtcReleaseScene(impl_->scene);
}

sh::BvhHit EmbreeScene::intersect(glm::vec3 o, glm::vec3 d, float tMin, float tMax) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh{};
  rh.ray.org_x = o.x, rh.ray.org_y = o.y, rh.ray.org_z = o.z;
  rh.ray.dir_x = d.x, rh.ray.dir_y = d.y, rh.ray.dir_z = d.z;
  rh.ray.tnear = tMin;
  rh.ray.tfar = tMax;
  rh.ray.mask = 0xffffffffu;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &context, &rh);
  sh::BvhHit hit{};
  hit.t = rh.ray.tfar;
  hit.prim = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? sh::BVH_NONE : rh.hit.primID;
  hit.u = rh.hit.u;
  hit.v = rh.hit.v;
  return hit;
}

bool EmbreeScene::occluded(glm::vec3 o, glm::vec3 d, float tMin, float tMax) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray{};
  ray.org_x = o.x, ray.org_y = o.y, ray.org_z = o.z;
  ray.dir_x = d.x, ray.dir_y = d.y, ray.dir_z = d.z;
  ray.tnear = tMin;
  ray.tfar = tMax;
  ray.mask = 0xffffffffu;
  rtcOccluded1(impl_->scene, &context, &ray);
  return ray.tfar == -std::numeric_limits<float>::infinity();
}

}  // namespace plume::geo
