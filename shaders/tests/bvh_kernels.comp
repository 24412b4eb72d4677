// Tier c (DESIGN §7): surface/bvh.glsl on the device for tests/test_gpu_bvh.cpp, which casts the
// same rays with Embree (rtcIntersect1, rtcOccluded1) and compares. One thread per ray.
#version 450
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;

#include "../shared/bvh.h"

// The tree as one texel buffer of uvec4 (shared/bvh.h), read as surface/surfaces.glsl reads it.
#include "../surface/texels.glsl"
layout(binding = 0) uniform usamplerBuffer bvhTexels;
#define BVH_TEXEL(i) SURF_TEXEL(bvhTexels, i)
#include "../surface/bvh.glsl"

struct RayCase {
  vec4 org;  // xyz: origin; w: tMin
  vec4 dir;  // xyz: direction; w: tMax of the closest-hit query
  vec4 any;  // x: tMax of the any-hit query
};
struct RayResult {
  BvhHit closest;
  BvhHit any;  // the any-hit traversal's hit (prim BVH_NONE: none), as bvh_any sees it
};
layout(std430, binding = 1) readonly buffer Cases { RayCase cases[]; };
layout(std430, binding = 2) writeonly buffer Results { RayResult results[]; };
layout(push_constant) uniform Push { uint count; } pc;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.count) return;
  RayCase c = cases[i];
  RayResult o;
  o.closest = bvh_closest(c.org.xyz, c.dir.xyz, c.org.w, c.dir.w);
  o.any = bvh_traverse(bvh_ray(c.org.xyz, c.dir.xyz), c.org.w, c.any.x, true);
  results[i] = o;
}
