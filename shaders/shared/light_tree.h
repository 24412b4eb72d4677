// The light tree over the emissive triangles (render/gpu_surfaces.cpp builds it, surface/
// surfaces.glsl samples it): a binary tree whose nodes bound their triangles' positions (a box),
// front normals (a cone) and power, so that a shading point x picks a triangle by descending from
// the root, choosing each child in proportion to an importance that falls off with distance and
// vanishes where no triangle below can face x (Conty Estevez and Kulla 2018, "Importance Sampling
// of Many Lights with Adaptive Tree Splitting"; pbrt-v4's BVHLightSampler). Among thousands of
// small lamps the ones near x and facing it get most samples, which a choice by power alone
// cannot do (notes/city.md). Shared by C++ and GLSL: the tests descend the tree with this code.
//
// Correctness needs one property only: importance 0 where no triangle of the node can send light
// to x (then the descent never picks what it cannot reach, and the probability of every
// reachable triangle is the product of its choices, which surf_emitter_pdf_at recomputes from the
// triangle's trail of left/right turns). The bound is conservative: for any point q of the box
// the direction q -> x is within theta_b (the bounding sphere's half-angle seen from x) of the
// direction centre -> x, and every front normal within theta_o of the axis, so no triangle faces
// x where theta_w - theta_o - theta_b >= 90 degrees.
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

// The node's importance for a shading point x (see above; 0 only where nothing below faces x).
PLUME_FN float lt_importance(GpuLightNode nd, vec3 x) {
  if (!(nd.power > 0.0f)) return 0.0f;
  vec3 c = 0.5f * (nd.boxMin + nd.boxMax);
  vec3 d = x - c;
  float dist2 = dot(d, d);
  vec3 diag = nd.boxMax - nd.boxMin;
  float r2 = 0.25f * dot(diag, diag);  // the bounding sphere's radius, squared
  if (dist2 <= r2) return nd.power / max(r2, 1e-20f);  // x inside the sphere: no angular bound
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
  return nd.power * cosP / dist2;
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

// The triangle (input index) that the descent from the root picks for x with u in [0, 1) (one
// number, rescaled at each level), and its probability in pmf (0: no triangle can light x).
PLUME_FN uint lt_sample(vec3 x, float u, OUT(float) pmf) {
  pmf = 1.0f;
  GpuLightNode nd = LT_NODE(0u);
  while ((nd.child & LT_LEAF) == 0u) {
    GpuLightNode a = LT_NODE(nd.child);
    GpuLightNode b = LT_NODE(nd.child + 1u);
    float p0 = lt_first_child_probability(lt_importance(a, x), lt_importance(b, x));
    if (p0 < 0.0f) {
      pmf = 0.0f;
      return 0u;
    }
    if (u < p0) {
      u = u / p0;
      pmf *= p0;
      nd = a;
    } else {
      u = (u - p0) / (1.0f - p0);
      pmf *= 1.0f - p0;
      nd = b;
    }
    u = min(u, 0.99999994f);
  }
  return nd.child & ~LT_LEAF;
}

// The probability with which lt_sample picks the triangle whose trail is `trail` at x: bit k is
// the turn at depth k (1: the second child), and a 1 above the last turn; 0: not in the tree.
// Two nodes read per level, the children, as lt_sample reads them (the next pair's index is the
// chosen child's `child`).
PLUME_FN float lt_pmf(vec3 x, uint trail) {
  if (trail == 0u) return 0.0f;
  float pmf = 1.0f;
  uint child = LT_NODE(0u).child;
  while (trail > 1u) {
    GpuLightNode a = LT_NODE(child);
    GpuLightNode b = LT_NODE(child + 1u);
    float p0 = lt_first_child_probability(lt_importance(a, x), lt_importance(b, x));
    if (p0 < 0.0f) return 0.0f;
    bool second = (trail & 1u) != 0u;
    pmf *= second ? 1.0f - p0 : p0;
    child = second ? b.child : a.child;
    trail = trail >> 1u;
  }
  return pmf;
}

PLUME_NS_END

#endif
