// The light tree over the emissive triangles (render/gpu_surfaces.cpp builds it, surface/
// surfaces.glsl samples it): a binary tree whose nodes bound their triangles' positions (a box),
// front normals (a cone) and power, so that a shading point x picks a triangle by descending from
// the root, two levels a step, choosing among a node's grandchildren in proportion to an
// importance that falls off with distance and vanishes where no triangle below can face x (Conty
// Estevez and Kulla 2018, "Importance Sampling of Many Lights with Adaptive Tree Splitting";
// pbrt-v4's BVHLightSampler). Among thousands of small lamps the ones near x and facing it get
// most samples, which a choice by power alone cannot do (notes/city.md). Shared by C++ and GLSL:
// the tests descend the tree with this code.
//
// Correctness needs one property only: importance 0 where no triangle of the node can send light
// to x (then the descent never picks what it cannot reach, and the probability of every
// reachable triangle is the product of its choices, which surf_emitter_pdf_at recomputes from the
// triangle's trail of left/right turns). The bound is conservative: for any point q of the box
// the direction q -> x is within theta_b (the bounding sphere's half-angle seen from x) of the
// direction centre -> x, and every front normal within theta_o of the axis, so no triangle faces
// x where theta_w - theta_o - theta_b >= 90 degrees.
//
// How much a node weighs beside the other candidates of its step (the descent below) is an
// estimate only (any positive value where light can arrive keeps the estimators unbiased), and
// the distance term decides it: the node's power
// times the mean of 1 / d² over its bounding sphere as if its emitters filled it, seen from x
// (exact for a uniform ball: 3/4 (2 + (1 - a²)/a ln|(1 + a)/(1 - a)|) / r² at a = D / r; 3 / r² at
// its centre, where 1 / D² would be infinite). A node's sphere that holds x holds emitters near x,
// and its sibling's are farther: on the bundled city's ground 0.04 under a street lamp the lamp's
// triangle had probability 0.019 when the distance was clamped at the radius (the importance
// P / r² inside the sphere) and its ancestors lost 5-45% to their siblings at every level
// (notes/city.md "Session 35").
//
// A shading point on a surface also has a receiver: its geometric normal n turned to the side light
// arrives from (every BSDF reflects only; integrator/vertex.glsl vtx_reflects), which no light
// behind it reaches. The same sphere bounds the directions x -> q, so with theta_i the angle
// between n and x -> centre, no point of the box lies in front of n where theta_i - theta_b >= 90
// degrees, and the importance is 0 there; elsewhere it carries the largest cosine at the receiver,
// cos(max(0, theta_i - theta_b)) (pbrt-v4's BVHLightSampler; its absolute value there, for BSDFs
// that transmit). A point in a medium passes n = 0: no receiver bound. The bound is computed with
// a slack of LT_RECEIVER_SLACK in the cosine (the rays leave from x pushed off the surface, and the
// bound must hold there too), and a node within the slack keeps LT_RECEIVER_FLOOR of its weight.
// The sampling and every MIS weight that evaluates these probabilities pass the same receiver for
// a vertex (its normal turned against the arriving ray, or towards the ray that leaves it).
#ifndef PLUME_SHARED_LIGHT_TREE_H
#define PLUME_SHARED_LIGHT_TREE_H

#include "common.h"

PLUME_NS_BEGIN

const uint LT_LEAF = 0x80000000u;  // GpuLightNode.child of a leaf: LT_LEAF | its triangle

// A node: inner nodes have two children at child and child + 1; a leaf is one triangle.
struct GpuLightNode {
  vec3 boxMin;
  float power;    // the triangles' emitted power (luminance of radiance x area), summed
  vec3 boxMax;
  float cosCone;  // every front normal below is within acos(cosCone) of axis (-1: any direction)
  vec3 axis;
  uint child;     // first child, or LT_LEAF | triangle (input index)
};

const float LT_RECEIVER_SLACK = 0.01f;
const float LT_RECEIVER_FLOOR = 0.01f;

// The node's importance for a shading point x with receiver normal n (0: none; see above): 0 only
// where nothing below faces x, or lies in front of n.
PLUME_FN float lt_importance(GpuLightNode nd, vec3 x, vec3 n) {
  if (!(nd.power > 0.0f)) return 0.0f;
  vec3 c = 0.5f * (nd.boxMin + nd.boxMax);
  vec3 d = x - c;
  float dist2 = dot(d, d);
  vec3 diag = nd.boxMax - nd.boxMin;
  float r2 = 0.25f * dot(diag, diag);  // the bounding sphere's radius, squared
  // The falloff: the mean of 1 / d² over a ball of radius r whose centre is at distance D from
  // x, 3 / r² at D = 0, 1.5 / r² at D = r, 1 / D² far off; approximated by 1 / max(D² - r²/3,
  // r²/3), exact at those three and within 37% between (at most 1.36x, at D = 0.82 r; see above).
  float meanInvD2 = 1.0f / max(max(dist2 - r2 / 3.0f, r2 / 3.0f), 1e-20f);
  if (dist2 <= r2) return nd.power * meanInvD2;  // x inside the sphere: no angular bound
  float dist = sqrt(dist2);
  float cosW = dot(nd.axis, d) / dist;  // angle between the axis and centre -> x
  float sinW = sqrt(max(0.0f, 1.0f - cosW * cosW));
  float cosO = nd.cosCone;
  float sinO = sqrt(max(0.0f, 1.0f - cosO * cosO));
  // theta_w - theta_o, clamped at 0
  float cosWO = 1.0f;
  float sinWO = 0.0f;
  if (cosW < cosO) {
    cosWO = cosW * cosO + sinW * sinO;
    sinWO = sinW * cosO - cosW * sinO;
  }
  // minus theta_b (sin^2 theta_b = r2 / dist2), clamped at 0
  float sinB = sqrt(r2 / dist2);
  float cosB = sqrt(max(0.0f, 1.0f - r2 / dist2));
  float cosP = 1.0f;
  if (cosWO < cosB) cosP = cosWO * cosB + sinWO * sinB;
  if (!(cosP > 0.0f)) return 0.0f;
  if (dot(n, n) > 0.0f) {
    // cos(max(0, theta_i - theta_b)), theta_i between n and x -> centre (= -d)
    float cosI = -dot(n, d) / dist;
    float sinI = sqrt(max(0.0f, 1.0f - cosI * cosI));
    float cosIB = cosI >= cosB ? 1.0f : cosI * cosB + sinI * sinB;
    if (!(cosIB > -LT_RECEIVER_SLACK)) return 0.0f;
    cosP *= max(cosIB, LT_RECEIVER_FLOOR);
  }
  return nd.power * cosP * meanInvD2;
}

// The probability of the first child (a, b: the children's importances); -1 where neither can
// light x.
PLUME_FN float lt_first_child_probability(float a, float b) {
  float s = a + b;
  return s > 0.0f ? a / s : -1.0f;
}

PLUME_NS_END

#ifdef __cplusplus
#include <cstddef>
static_assert(sizeof(plume::shared::GpuLightNode) == 48, "GpuLightNode layout");
static_assert(offsetof(plume::shared::GpuLightNode, axis) == 32, "GpuLightNode layout");
#endif

#endif

// The descent, over the nodes as LT_NODE(i) gives them (a buffer in GLSL; in the tests
// tests/support/light_tree.h): compiled by the first inclusion with LT_NODE defined.
#if defined(LT_NODE) && !defined(PLUME_SHARED_LIGHT_TREE_DESCENT)
#define PLUME_SHARED_LIGHT_TREE_DESCENT

PLUME_NS_BEGIN

// The descent goes down two levels a step: from the pair of children at `child` it picks one of
// their children (a child that is a leaf stands for itself), each in proportion to its
// importance. A grandchild's importance sees its emitters from nearer than its parent's does (a
// smaller sphere), so under a street lamp the lamp's side of the tree weighs more; and it costs as
// many importances as two binary levels, in half the loop's iterations (notes/city.md "Session
// 36"). The choice is made as two binary ones: the child by the sum of its pair, then the
// grandchild within it, so the probabilities and the rescaled number are
// lt_first_child_probability's.
// lt_step fills the four candidates' node indices and importances: slots x, y under the first
// child, z, w under the second; a leaf child fills its first slot with itself and its second with
// the same index and importance 0.
PLUME_FN void lt_step(uint child, vec3 x, vec3 n, OUT(uvec4) node, OUT(vec4) w) {
  uint ca = LT_NODE(child).child;
  uint cb = LT_NODE(child + 1u).child;
  bool la = (ca & LT_LEAF) != 0u;
  bool lb = (cb & LT_LEAF) != 0u;
  node = uvec4(la ? child : ca, la ? child : ca + 1u, lb ? child + 1u : cb, lb ? child + 1u : cb + 1u);
  w = vec4(lt_importance(LT_NODE(node.x), x, n), la ? 0.0f : lt_importance(LT_NODE(node.y), x, n),
           lt_importance(LT_NODE(node.z), x, n), lb ? 0.0f : lt_importance(LT_NODE(node.w), x, n));
}

// The triangle (input index) that the descent from the root picks for x (receiver normal n, 0:
// none) with u in [0, 1) (one number, rescaled at each choice), and its probability in pmf (0: no
// triangle can light x).
PLUME_FN uint lt_sample(vec3 x, vec3 n, float u, OUT(float) pmf) {
  pmf = 1.0f;
  uint child = LT_NODE(0u).child;
  while ((child & LT_LEAF) == 0u) {
    uvec4 node;
    vec4 w;
    lt_step(child, x, n, node, w);
    float p0 = lt_first_child_probability(w.x + w.y, w.z + w.w);
    if (p0 < 0.0f) {
      pmf = 0.0f;
      return 0u;
    }
    bool second = u >= p0;
    u = second ? (u - p0) / (1.0f - p0) : u / p0;
    pmf *= second ? 1.0f - p0 : p0;
    u = min(u, 0.99999994f);
    // within the chosen pair (its sum is positive: a pair of sum 0 has probability 0)
    vec2 pw = second ? vec2(w.z, w.w) : vec2(w.x, w.y);
    uvec2 pn = second ? uvec2(node.z, node.w) : uvec2(node.x, node.y);
    float p1 = lt_first_child_probability(pw.x, pw.y);
    bool second1 = u >= p1;
    u = second1 ? (u - p1) / (1.0f - p1) : u / p1;
    pmf *= second1 ? 1.0f - p1 : p1;
    u = min(u, 0.99999994f);
    child = LT_NODE(second1 ? pn.y : pn.x).child;
  }
  return child & ~LT_LEAF;
}

// The probability with which lt_sample picks the triangle whose trail is `trail` at x (receiver
// normal n): bit k is the turn at depth k (1: the second child), and a 1 above the last turn; 0:
// not in the tree. The same steps as lt_sample, two turns each (one where the child is a leaf).
PLUME_FN float lt_pmf(vec3 x, vec3 n, uint trail) {
  if (trail == 0u) return 0.0f;
  float pmf = 1.0f;
  uint child = LT_NODE(0u).child;
  while (trail > 1u) {
    uvec4 node;
    vec4 w;
    lt_step(child, x, n, node, w);
    float p0 = lt_first_child_probability(w.x + w.y, w.z + w.w);
    if (p0 < 0.0f) return 0.0f;
    bool second = (trail & 1u) != 0u;
    trail = trail >> 1u;
    pmf *= second ? 1.0f - p0 : p0;
    vec2 pw = second ? vec2(w.z, w.w) : vec2(w.x, w.y);
    uvec2 pn = second ? uvec2(node.z, node.w) : uvec2(node.x, node.y);
    if (pn.x == pn.y) break;  // the child is a leaf: the trail ends here
    float p1 = lt_first_child_probability(pw.x, pw.y);
    if (p1 < 0.0f) return 0.0f;
    bool second1 = (trail & 1u) != 0u;
    trail = trail >> 1u;
    pmf *= second1 ? 1.0f - p1 : p1;
    child = LT_NODE(second1 ? pn.y : pn.x).child;
  }
  return pmf;
}

PLUME_NS_END

#endif
