// Language bridge for headers compiled both as GLSL (glslang, #version 450 with
// GL_GOOGLE_include_directive) and as C++20 with GLM. A handful of macros absorb the
// differences, in the manner of PNanoVDB.h:
//   PLUME_FN        `inline` in C++, nothing in GLSL
//   INOUT(T), OUT(T) reference parameters
//   PLUME_NS_BEGIN / PLUME_NS_END  namespace plume::shared { } in C++
// Write the shared code in the common subset: no constructors of structs (assign fields),
// float literals with an `f` suffix, uint literals with `u`, no recursion, no pointers.
#ifndef PLUME_SHARED_COMMON_H
#define PLUME_SHARED_COMMON_H

#ifdef __cplusplus
#include <glm/glm.hpp>
#include <cstdint>
#define PLUME_NS_BEGIN namespace plume::shared { using namespace glm; using uint = uint32_t;
#define PLUME_NS_END }
#define PLUME_FN inline
#define INOUT(T) T&
#define OUT(T) T&
#else
#define PLUME_NS_BEGIN
#define PLUME_NS_END
#define PLUME_FN
#define INOUT(T) inout T
#define OUT(T) out T
#endif

PLUME_NS_BEGIN

const float PLUME_PI = 3.14159265358979f;
const float PLUME_INV_PI = 0.318309886183791f;
const float PLUME_INV_4PI = 0.0795774715459477f;

// Orthonormal basis around a unit vector n (Duff et al. 2017, "Building an Orthonormal Basis,
// Revisited"), branch-free apart from the sign.
PLUME_FN void plume_onb(vec3 n, OUT(vec3) b1, OUT(vec3) b2) {
  float s = n.z >= 0.0f ? 1.0f : -1.0f;
  float a = -1.0f / (s + n.z);
  float b = n.x * n.y * a;
  b1 = vec3(1.0f + s * n.x * n.x * a, s * b, -s * n.x);
  b2 = vec3(b, s + n.y * n.y * a, -n.y);
}

PLUME_FN float plume_max3(vec3 v) { return max(v.x, max(v.y, v.z)); }

PLUME_NS_END

#endif
