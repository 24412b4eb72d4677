// Deterministic hash noise: an integer hash (lowbias32 by Chris Wellons), smooth value noise on
// the integer lattice and its fractal (fBm) sum. Pure functions of their arguments.
#include "volgen.h"

#include <cmath>

namespace volgen {

namespace {
uint32_t mix(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}
float smooth(float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); }  // quintic fade
}  // namespace

uint32_t hash32(uint32_t a, uint32_t b, uint32_t c, uint32_t d) {
  uint32_t h = mix(a + 0x9e3779b9u);
  h = mix(h ^ (b + 0x85ebca6bu));
  h = mix(h ^ (c + 0xc2b2ae35u));
  return mix(h ^ (d + 0x27d4eb2fu));
}

float hashUnit(uint32_t a, uint32_t b, uint32_t c, uint32_t d) {
  return float(hash32(a, b, c, d) >> 8) * (1.0f / 16777216.0f);
}

float valueNoise(float x, float y, float z, uint32_t seed) {
  float fx = std::floor(x), fy = std::floor(y), fz = std::floor(z);
  int ix = int(fx), iy = int(fy), iz = int(fz);
  float tx = smooth(x - fx), ty = smooth(y - fy), tz = smooth(z - fz);
  auto v = [&](int dx, int dy, int dz) {
    return 2.0f * hashUnit(uint32_t(ix + dx), uint32_t(iy + dy), uint32_t(iz + dz), seed) - 1.0f;
  };
  auto lerp = [](float a, float b, float t) { return a + (b - a) * t; };
  float x00 = lerp(v(0, 0, 0), v(1, 0, 0), tx), x10 = lerp(v(0, 1, 0), v(1, 1, 0), tx);
  float x01 = lerp(v(0, 0, 1), v(1, 0, 1), tx), x11 = lerp(v(0, 1, 1), v(1, 1, 1), tx);
  return lerp(lerp(x00, x10, ty), lerp(x01, x11, ty), tz);
}

float fbm(float x, float y, float z, int octaves, uint32_t seed) {
  float sum = 0, amp = 0.5f, norm = 0;
  for (int o = 0; o < octaves; ++o) {
    sum += amp * valueNoise(x, y, z, seed + uint32_t(o) * 1013u);
    norm += amp;
    x = x * 2.03f + 17.1f;  // slightly off 2 and shifted, so octaves do not line up
    y = y * 2.03f + 5.3f;
    z = z * 2.03f + 11.7f;
    amp *= 0.5f;
  }
  return sum / norm;
}

}  // namespace volgen
