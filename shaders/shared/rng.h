// Counter-based random numbers (DESIGN §2): the state is a hash of (pixel, frame, stream, seed)
// plus a draw counter, so any pass can regenerate any stream without stored seeds, and GLSL and
// C++ produce bit-identical streams (32-bit unsigned arithmetic only).
// Hash: pcg4d, Jarzynski & Olano, "Hash Functions for GPU Rendering", JCGT 9(3), 2020.
#ifndef PLUME_SHARED_RNG_H
#define PLUME_SHARED_RNG_H

#include "common.h"

PLUME_NS_BEGIN

// Named stream constants: every pass draws from its own stream.
const uint RNG_STREAM_CAMERA = 1u;
const uint RNG_STREAM_PATH = 2u;
const uint RNG_STREAM_CANDIDATES = 3u;
const uint RNG_STREAM_TEMPORAL = 4u;
const uint RNG_STREAM_SPATIAL = 5u;
const uint RNG_STREAM_SHADING = 6u;
const uint RNG_STREAM_TEST = 100u;

struct RngState {
  uvec4 key;
  uint counter;
};

PLUME_FN uvec4 rng_pcg4d(uvec4 v) {
  v = v * 1664525u + 1013904223u;
  v.x += v.y * v.w;
  v.y += v.z * v.x;
  v.z += v.x * v.y;
  v.w += v.y * v.z;
  v = v ^ (v >> 16u);
  v.x += v.y * v.w;
  v.y += v.z * v.x;
  v.z += v.x * v.y;
  v.w += v.y * v.z;
  return v;
}

PLUME_FN RngState rng_init(uvec2 pixel, uint frame, uint stream, uint seed) {
  RngState r;
  r.key = rng_pcg4d(uvec4(pixel.x, pixel.y, frame, seed ^ (stream * 0x9E3779B9u)));
  r.counter = 0u;
  return r;
}

// Four independent 32-bit words per draw.
PLUME_FN uvec4 rng_next4(INOUT(RngState) r) {
  r.counter += 1u;
  return rng_pcg4d(uvec4(r.key.x, r.key.y, r.key.z, r.key.w + r.counter));
}

PLUME_FN uint rng_uint(INOUT(RngState) r) { return rng_next4(r).x; }

// Uniform in [0, 1): the top 24 bits, exactly representable as float.
PLUME_FN float rng_to_float(uint x) { return float(x >> 8u) * (1.0f / 16777216.0f); }

PLUME_FN float rng_float(INOUT(RngState) r) { return rng_to_float(rng_uint(r)); }

PLUME_FN vec2 rng_float2(INOUT(RngState) r) {
  uvec4 h = rng_next4(r);
  return vec2(rng_to_float(h.x), rng_to_float(h.y));
}

PLUME_NS_END

#endif
