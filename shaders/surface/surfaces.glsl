// The scene's surfaces as the estimators see them (DESIGN §2 "Surfaces", §4.3): the BVH's
// bindings and traversal (surface/bvh.glsl), a hit's normals and material, emission leaving a
// triangle's front side, the emissive triangles as one light whose triangles a shading point picks
// from the light tree (shared/light_tree.h: power, distance, orientation), and ray origins pushed
// off a surface. Compiled only into scenes with
// surfaces (PLUME_HAS_SURFACES; PLUME_HAS_EMITTERS where some surface emits). The host side is
// render/gpu_surfaces.cpp; the CPU reference's own version is reference/surfaces.cpp.
// Requires scene/bindings.glsl.
#ifndef PLUME_SURFACE_SURFACES_GLSL
#define PLUME_SURFACE_SURFACES_GLSL

#include "../shared/bvh.h"
#include "../shared/surface_types.h"
#include "../shared/light_tree.h"

// The estimator's binding numbers may be shifted as a block (ReSTIR's passes use 11-15 for their
// own buffers: shared/bindings.h BIND_RS_SURFACES); the path tracer's are BIND_BVH ...
#ifndef PLUME_SURF_BINDING_SHIFT
#define PLUME_SURF_BINDING_SHIFT 0u
#endif
// Every array is a texel buffer of uvec4 (surface/texels.glsl says why).
#include "texels.glsl"
layout(binding = BIND_BVH + PLUME_SURF_BINDING_SHIFT) uniform usamplerBuffer bvhTexels;
#define BVH_TEXEL(i) SURF_TEXEL(bvhTexels, i)
#include "bvh.glsl"

layout(binding = BIND_SURF_TRIANGLES + PLUME_SURF_BINDING_SHIFT) uniform usamplerBuffer surfTriangleTexels;
layout(binding = BIND_SURF_MATERIALS + PLUME_SURF_BINDING_SHIFT) uniform usamplerBuffer surfMaterialTexels;

// Triangle prim's fields (GpuSurfaceTriangle: 6 texels), each read where it is needed.
uvec4 surf_triangle_texel(uint prim, uint k) { return SURF_TEXEL(surfTriangleTexels, 6u * prim + k); }
vec3 surf_vertex(uint prim, uint k) { return uintBitsToFloat(surf_triangle_texel(prim, k).xyz); }  // v0, v1, v2
uint surf_surface(uint prim) { return surf_triangle_texel(prim, 0u).w; }
// Material s (GpuSurfaceMaterial: 3 texels): its BSDF, and the radiance leaving its front side.
Bsdf surf_material_bsdf(uint s) {
  uvec4 a = SURF_TEXEL(surfMaterialTexels, 3u * s);
  uvec4 b = SURF_TEXEL(surfMaterialTexels, 3u * s + 1u);
  Bsdf f;
  f.color = uintBitsToFloat(a.xyz);
  f.type = a.w;
  f.alpha = uintBitsToFloat(b.x);
  f.pad0 = uintBitsToFloat(b.y);
  f.pad1 = uintBitsToFloat(b.z);
  f.pad2 = uintBitsToFloat(b.w);
  return f;
}
vec3 surf_material_emission(uint s) { return uintBitsToFloat(SURF_TEXEL(surfMaterialTexels, 3u * s + 2u).xyz); }

#ifdef PLUME_HAS_EMITTERS
layout(binding = BIND_EMITTERS + PLUME_SURF_BINDING_SHIFT) uniform usamplerBuffer surfLightNodeTexels;
// A light tree node (GpuLightNode: 3 texels).
GpuLightNode surf_light_node(uint i) {
  uvec4 a = SURF_TEXEL(surfLightNodeTexels, 3u * i);
  uvec4 b = SURF_TEXEL(surfLightNodeTexels, 3u * i + 1u);
  uvec4 c = SURF_TEXEL(surfLightNodeTexels, 3u * i + 2u);
  GpuLightNode n;
  n.boxMin = uintBitsToFloat(a.xyz);
  n.power = uintBitsToFloat(a.w);
  n.boxMax = uintBitsToFloat(b.xyz);
  n.cosCone = uintBitsToFloat(b.w);
  n.axis = uintBitsToFloat(c.xyz);
  n.child = c.w;
  return n;
}
#define LT_NODE(i) surf_light_node(i)
#include "../shared/light_tree.h"  // again, for the descent over the tree's texels
#endif

const float SURF_FAR = 3.0e38f;
// Ray origins leave a surface this far, relative to the point's magnitude (float traversal).
const float SURF_RELATIVE_OFFSET = 1e-4f;

// The unit geometric normal of the triangle's front side (counter-clockwise seen from it).
vec3 surf_normal(uint prim) {
  vec3 v0 = surf_vertex(prim, 0u);
  return normalize(cross(surf_vertex(prim, 1u) - v0, surf_vertex(prim, 2u) - v0));
}

// The shading normal at barycentrics uv (Embree's: p = (1 - u - v) v0 + u v1 + v v2): the mesh's
// interpolated normals where it has them, else the geometric normal.
vec3 surf_shading_normal(uint prim, vec2 uv, vec3 geometric) {
  if (surf_triangle_texel(prim, 2u).w == 0u) return geometric;  // hasNormals
  vec3 n0 = uintBitsToFloat(surf_triangle_texel(prim, 3u).xyz);
  vec3 n1 = uintBitsToFloat(surf_triangle_texel(prim, 4u).xyz);
  vec3 n2 = uintBitsToFloat(surf_triangle_texel(prim, 5u).xyz);
  vec3 n = (1.0f - uv.x - uv.y) * n0 + uv.x * n1 + uv.y * n2;
  float len = length(n);
  return len > 0.0f ? n / len : geometric;
}

Bsdf surf_bsdf(uint prim) { return surf_material_bsdf(surf_surface(prim)); }

// The radiance a ray of direction dir sees where it hits triangle prim (front normal n): the
// surface's emission on the front side, nothing on the back.
vec3 surf_emitted(uint prim, vec3 n, vec3 dir) {
  return dot(n, dir) < 0.0f ? surf_material_emission(surf_surface(prim)) : vec3(0.0f);
}

float surf_offset_length(vec3 p) { return SURF_RELATIVE_OFFSET * (1.0f + plume_max3(abs(p))); }

// A ray's origin at surface point p (geometric normal n) towards w: pushed off to w's side, so
// that the next traversal cannot find the same triangle.
vec3 surf_offset_origin(vec3 p, vec3 n, vec3 w) {
  return p + ((dot(n, w) < 0.0f ? -1.0f : 1.0f) * surf_offset_length(p)) * n;
}

// Whether a surface lies on the ray within (0, tMax) (shadow rays).
bool surf_occluded(vec3 o, vec3 d, float tMax) { return bvh_any(o, d, 0.0f, tMax); }

// The point of triangle prim at barycentrics b = (b1, b2) of v1 and v2 (Embree's (u, v)).
vec3 surf_triangle_point(uint prim, vec2 b) {
  return (1.0f - b.x - b.y) * surf_vertex(prim, 0u) + b.x * surf_vertex(prim, 1u) + b.y * surf_vertex(prim, 2u);
}

#ifdef PLUME_HAS_EMITTERS
// A uniform point of a triangle from u in [0,1)² (the square-root map, as the reference), as
// barycentrics (b1, b2) of v1 and v2.
vec2 surf_uniform_barycentrics(vec2 u) {
  float r = sqrt(u.x);
  return vec2(r * (1.0f - u.y), r * u.y);
}

vec3 surf_emission(uint prim) { return surf_material_emission(surf_surface(prim)); }

// An emissive triangle's 1 / area (0: dark) and its trail in the light tree.
float surf_emitter_inv_area(uint prim) { return uintBitsToFloat(surf_triangle_texel(prim, 1u).w); }
uint surf_light_trail(uint prim) { return surf_triangle_texel(prim, 3u).w; }

// The receiver normal of a surface vertex on triangle prim for the light tree (shared/light_tree.h):
// its geometric normal turned towards w, a direction on the side light arrives from (the ray that
// leaves the vertex, or minus the one that arrived).
vec3 surf_receiver(uint prim, vec3 w) {
  vec3 n = surf_normal(prim);
  return dot(n, w) < 0.0f ? -n : n;
}

// A point on the emissive triangles for the shading point x with receiver normal n (0: a point
// in a medium; surf_receiver) from u in [0,1)³: a triangle from the light tree (u.x), a uniform
// point in it (u.yz) as barycentrics. Returns its area density (0: no emitter can light x).
float surf_sample_emitter_at(vec3 x, vec3 n, vec3 u, out uint prim, out vec2 barycentrics) {
  float pmf;
  prim = lt_sample(x, n, u.x, pmf);
  barycentrics = surf_uniform_barycentrics(u.yz);
  return pmf > 0.0f ? pmf * surf_emitter_inv_area(prim) : 0.0f;
}

// The area density with which surf_sample_emitter_at(x, n) picks a point of triangle prim (0: it
// is dark, or cannot light x).
float surf_emitter_pdf_at(uint prim, vec3 x, vec3 n) {
  float invArea = surf_emitter_inv_area(prim);
  return invArea > 0.0f ? lt_pmf(x, n, surf_light_trail(prim)) * invArea : 0.0f;
}
#endif

#endif
