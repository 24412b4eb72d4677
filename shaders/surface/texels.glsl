// The surfaces' arrays as texel buffers of uvec4 (render/gpu_surfaces.cpp uploads each struct's
// bytes as it is laid out for C++ and std430: shared/bvh.h, shared/surface_types.h,
// shared/light_tree.h; every struct is a whole number of 16-byte texels). A lane that reads a
// node or a triangle of its own makes one gather per texel instead of a scalar loop over the
// lanes per word, which a storage buffer costs on a SIMD back end such as lavapipe
// (docs/architecture.md, "Descriptor kinds"). Floats travel as their bits (a UINT format: no
// conversion can touch them). The caller names the buffer.
#ifndef PLUME_SURFACE_TEXELS_GLSL
#define PLUME_SURFACE_TEXELS_GLSL

#include "../shared/bvh.h"

#define SURF_TEXEL(buf, i) texelFetch(buf, int(i))

BvhNode bvh_node_from(uvec4 a, uvec4 b, uvec4 c, uvec4 d) {
  BvhNode n;
  n.lo0 = uintBitsToFloat(a.xyz);
  n.ref0 = a.w;
  n.hi0 = uintBitsToFloat(b.xyz);
  n.count0 = b.w;
  n.lo1 = uintBitsToFloat(c.xyz);
  n.ref1 = c.w;
  n.hi1 = uintBitsToFloat(d.xyz);
  n.count1 = d.w;
  return n;
}

BvhTriangle bvh_triangle_from(uvec4 a, uvec4 b, uvec4 c) {
  BvhTriangle t;
  t.v0 = uintBitsToFloat(a.xyz);
  t.prim = a.w;
  t.v1 = uintBitsToFloat(b.xyz);
  t.pad0 = b.w;
  t.v2 = uintBitsToFloat(c.xyz);
  t.pad1 = c.w;
  return t;
}

#endif
