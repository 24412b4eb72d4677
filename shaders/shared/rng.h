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
const uint RNG_STREAM_COLOUR = 7u;  // ReSTIR's colour weights' own walks (restir/colour.glsl)
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

// A walk's own generator (the volume's tracking loops, shaders/volume/walk.glsl): xoshiro128+
// (Blackman & Vigna, "Scrambled linear pseudorandom number generators", 2021), its 128-bit state
// one draw of the stream that walks. Each tentative collision takes two numbers; through the
// counter-based hash each would cost a pcg4d, whose eight dependent multiplies are the longest
// chain of a tracking step on a SIMD back end that runs one subgroup at a time (lavapipe), where
// xoshiro128+ is a few shifts and xors. Only the top 24 bits are used (rng_to_float): those of
// xoshiro128+ pass BigCrush; its weak low bits are never read. The stream's counter advances once
// per walk, so every walk's numbers are still a function of (pixel, frame, stream, seed, counter).
struct RngWalk {
  uvec4 s;
};

PLUME_FN RngWalk rng_walk_init(INOUT(RngState) r) {
  RngWalk g;
  g.s = rng_next4(r);
  if (g.s.x == 0u && g.s.y == 0u && g.s.z == 0u && g.s.w == 0u) g.s.x = 1u;  // (the one state it never leaves)
  return g;
}

// The next 32 bits (use the top ones: rng_to_float).
PLUME_FN uint rng_walk_next(INOUT(RngWalk) g) {
  uint result = g.s.x + g.s.w;
  uint t = g.s.y << 9u;
  g.s.z ^= g.s.x;
  g.s.w ^= g.s.y;
  g.s.y ^= g.s.z;
  g.s.x ^= g.s.w;
  g.s.z ^= t;
  g.s.w = (g.s.w << 11u) | (g.s.w >> 21u);
  return result;
}

PLUME_NS_END

#endif
