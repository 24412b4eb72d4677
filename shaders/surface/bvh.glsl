// Ray traversal of the surfaces' BVH (layout: shared/bvh.h; built by geometry/bvh.cpp): the
// closest hit and any hit (shadow rays) over t in (tMin, tMax). The includer provides the
// storage, one texel buffer of uvec4 laid out as shared/bvh.h says, through BVH_TEXEL(i).
//
// Ray/triangle: the watertight test of Woop, Benthin and Wald 2013 ("Watertight Ray/Triangle
// Intersection", JCGT 2(1)): the vertices are translated to the ray origin and sheared so that
// the ray runs along +z; the 2D edge functions U, V, W then decide, and a ray through a shared
// edge or vertex hits at least one of the triangles that share it, because the neighbours
// evaluate that edge's function with the same operands in the same float operations (`precise`
// keeps the compiler from fusing them differently). Both sides of a triangle are hit.
// Ray/box: slabs with the far distance scaled by 1 + 2 gamma(3) (Ize 2013, "Robust BVH Ray
// Traversal"), so float rounding never misses a box that the ray touches; an axis the ray does
// not move along is "every t" or "no t" by whether the origin lies in the slab (the product
// 0 * inf would be NaN).
// Traversal: a stack of PLUME_BVH_STACK entries (the host compiles the kernels with the built
// tree's depth, the most far children that can wait at once: one per inner node on the path to
// the current item; BVH_STACK_SIZE where it is not defined), nearer child first; a stack entry
// packs a child reference as (ref << 3) | count (count 0: an inner node, 1..4: a leaf's
// triangles). One loop iteration visits one node or tests one triangle (a leaf of n triangles stays the current item,
// ref + 1 and n - 1, for n iterations): a SIMD back end runs the whole loop body on every
// iteration (../shared/docs/LAVAPIPE.md), and a triangle loop nested in it ran at least once per
// node visit of any lane (lavapipe: the city's path tracer 12 % faster without it, same hits). For
// the same reason an iteration reads its item, node or triangle, with one set of four texel reads
// (the layout of shared/bvh.h) instead of a node's four and a triangle's three (the city's path
// tracer another 5-8 %). The stack is a shift register (push moves every entry down one place,
// pop up one place, all with constant indices): a private array indexed by a variable becomes
// per-lane scalar stores and loads on lavapipe; in registers, at the city's 17 entries, its path
// tracer's extension and shading ran 6-7 % faster (notes/bench/kernels.md "Session 20"). Its
// cost grows with the entries (session 19: -8 % at 24, -2 % at 48), hence the tree's own depth.
#ifndef PLUME_SURFACE_BVH_GLSL
#define PLUME_SURFACE_BVH_GLSL

#include "../shared/bvh.h"

#ifndef PLUME_BVH_STACK
#define PLUME_BVH_STACK BVH_STACK_SIZE
#endif

const float BVH_FAR_SCALE = 1.0000004f;  // 1 + 2 gamma(3), gamma(n) = n eps / (1 - n eps), eps = 2^-24
const float BVH_BIG = 3.0e38f;

struct BvhRay {
  vec3 org;
  vec3 dir;
  vec3 invDir;
  bvec3 still;   // dir[a] == 0: the ray does not move along axis a
  vec3 shear;    // Sx, Sy, Sz of the watertight test
  uvec3 axes;    // kx, ky, kz
};

BvhRay bvh_ray(vec3 org, vec3 dir) {
  BvhRay r;
  r.org = org;
  r.dir = dir;
  r.invDir = 1.0f / dir;
  r.still = equal(dir, vec3(0.0f));
  vec3 a = abs(dir);
  uint kz = a.x > a.y ? (a.x > a.z ? 0u : 2u) : (a.y > a.z ? 1u : 2u);
  uint kx = kz == 2u ? 0u : kz + 1u;
  uint ky = kx == 2u ? 0u : kx + 1u;
  if (dir[kz] < 0.0f) {  // keep the winding: swap x and y when the ray runs along -z
    uint s = kx;
    kx = ky;
    ky = s;
  }
  r.axes = uvec3(kx, ky, kz);
  r.shear = vec3(dir[kx] / dir[kz], dir[ky] / dir[kz], 1.0f / dir[kz]);
  return r;
}

// Entry distance into the box, or BVH_BIG when the ray misses it within [tMin, tMax].
float bvh_box(BvhRay r, vec3 lo, vec3 hi, float tMin, float tMax) {
  vec3 t0 = (lo - r.org) * r.invDir;
  vec3 t1 = (hi - r.org) * r.invDir;
  vec3 tn = min(t0, t1);
  vec3 tf = max(t0, t1);
  bvec3 inside = bvec3(step(lo, r.org) * step(r.org, hi));
  vec3 flatNear = mix(vec3(BVH_BIG), vec3(-BVH_BIG), inside);
  tn = mix(tn, flatNear, r.still);
  tf = mix(tf, -flatNear, r.still);
  float tNear = max(max(tn.x, tn.y), max(tn.z, tMin));
  float tFar = min(min(tf.x, tf.y), min(tf.z, tMax)) * BVH_FAR_SCALE;
  return tNear <= tFar ? tNear : BVH_BIG;
}

// Watertight ray/triangle test; on a hit with t in (tMin, tMax): t and Embree's barycentrics
// (u of v1, v of v2).
bool bvh_triangle(BvhRay r, BvhTriangle tri, float tMin, float tMax, out float t, out vec2 uv) {
  vec3 A = tri.v0 - r.org;
  vec3 B = tri.v1 - r.org;
  vec3 C = tri.v2 - r.org;
  uint kx = r.axes.x, ky = r.axes.y, kz = r.axes.z;
  precise float Ax = A[kx] - r.shear.x * A[kz];
  precise float Ay = A[ky] - r.shear.y * A[kz];
  precise float Bx = B[kx] - r.shear.x * B[kz];
  precise float By = B[ky] - r.shear.y * B[kz];
  precise float Cx = C[kx] - r.shear.x * C[kz];
  precise float Cy = C[ky] - r.shear.y * C[kz];
  precise float U = Cx * By - Cy * Bx;
  precise float V = Ax * Cy - Ay * Cx;
  precise float W = Bx * Ay - By * Ax;
  t = 0.0f;
  uv = vec2(0.0f);
  if ((U < 0.0f || V < 0.0f || W < 0.0f) && (U > 0.0f || V > 0.0f || W > 0.0f)) return false;
  float det = U + V + W;
  if (det == 0.0f) return false;  // the ray lies in the triangle's plane
  float T = U * (r.shear.z * A[kz]) + V * (r.shear.z * B[kz]) + W * (r.shear.z * C[kz]);
  float rcp = 1.0f / det;
  t = T * rcp;
  if (!(t > tMin && t < tMax)) return false;
  uv = vec2(V * rcp, W * rcp);
  return true;
}

// The one traversal loop; anyHit is a constant at each call site (bvh_closest, bvh_any), so each
// inlined copy keeps only its own exit.
BvhHit bvh_traverse(BvhRay r, float tMin, float tMax, const bool anyHit) {
  BvhHit hit;
  hit.t = tMax;
  hit.prim = BVH_NONE;
  hit.u = 0.0f;
  hit.v = 0.0f;
  uint stack[PLUME_BVH_STACK];
  int sp = 0;  // entries in use
  uint item = 0u;  // the root, an inner node
  uint firstTriangle = BVH_TEXEL(0u).x;  // the header: triangle 0's texel
  while (true) {
    uint count = item & 7u;
    uint ref = item >> 3u;
    uint at = count == 0u ? BVH_HEADER_TEXELS + BVH_NODE_TEXEL_COUNT * ref : firstTriangle + BVH_TRIANGLE_TEXEL_COUNT * ref;
    uvec4 q0 = BVH_TEXEL(at);
    uvec4 q1 = BVH_TEXEL(at + 1u);
    uvec4 q2 = BVH_TEXEL(at + 2u);
    uvec4 q3 = BVH_TEXEL(at + 3u);
    if (count == 0u) {
      BvhNode node = bvh_node_from(q0, q1, q2, q3);
      float d0 = node.ref0 == BVH_NONE ? BVH_BIG : bvh_box(r, node.lo0, node.hi0, tMin, hit.t);
      float d1 = node.ref1 == BVH_NONE ? BVH_BIG : bvh_box(r, node.lo1, node.hi1, tMin, hit.t);
      uint c0 = (node.ref0 << 3u) | node.count0;
      uint c1 = (node.ref1 << 3u) | node.count1;
      if (d0 < BVH_BIG && d1 < BVH_BIG) {
        bool firstNear = d0 <= d1;
        for (int k = PLUME_BVH_STACK - 1; k > 0; --k) stack[k] = stack[k - 1];
        stack[0] = firstNear ? c1 : c0;
        ++sp;
        item = firstNear ? c0 : c1;
        continue;
      }
      if (d0 < BVH_BIG || d1 < BVH_BIG) {
        item = d0 < BVH_BIG ? c0 : c1;
        continue;
      }
    } else {
      BvhTriangle tri = bvh_triangle_from(q0, q1, q2);
      float t;
      vec2 uv;
      if (bvh_triangle(r, tri, tMin, hit.t, t, uv)) {
        hit.t = t;
        hit.prim = tri.prim;
        hit.u = uv.x;
        hit.v = uv.y;
        if (anyHit) return hit;
      }
      if (count > 1u) {
        item = ((ref + 1u) << 3u) | (count - 1u);
        continue;
      }
    }
    if (sp == 0) break;
    item = stack[0];
    for (int k = 0; k < PLUME_BVH_STACK - 1; ++k) stack[k] = stack[k + 1];
    --sp;
  }
  return hit;
}

BvhHit bvh_closest(vec3 org, vec3 dir, float tMin, float tMax) {
  return bvh_traverse(bvh_ray(org, dir), tMin, tMax, false);
}

bool bvh_any(vec3 org, vec3 dir, float tMin, float tMax) {
  return bvh_traverse(bvh_ray(org, dir), tMin, tMax, true).prim != BVH_NONE;
}

#endif
