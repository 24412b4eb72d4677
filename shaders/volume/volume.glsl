// The bridge between the tracking algorithms and the baked volume: trilinear density with
// exact weights (8 texelFetch, DESIGN §3), per-brick majorants, delta tracking and ratio
// tracking. Mirrors media/bake_lookup.cpp texel for texel. Requires bindings.glsl.
#ifndef PLUME_VOLUME_GLSL
#define PLUME_VOLUME_GLSL

#include "../shared/dda.h"
#include "../shared/rng.h"

const int VOL_BRICK = 8;
const int VOL_TEXELS = 10;
const uint VOL_MAX_STEPS = 1u << 20;  // per tracking call; hits are counted in volCounters[0]

// The indirection holds each brick's atlas slot as packed slot coordinates (10 bits per axis,
// see GpuVolumeResources); 0 is the all-zero slot. No integer division in the hot loop.
uint vol_packed_slot(ivec3 brick) {
  ivec3 r = brick - vol.brickOrigin.xyz;
  if (any(lessThan(r, ivec3(0))) || any(greaterThanEqual(r, vol.brickDims.xyz))) return 0u;
  return volIndirection[(r.z * vol.brickDims.y + r.y) * vol.brickDims.x + r.x];
}

ivec3 vol_slot_origin(uint packed) {
  return ivec3(int(packed & 1023u), int((packed >> 10u) & 1023u), int(packed >> 20u)) * VOL_TEXELS;
}

// Density d at an index-space point (not yet multiplied by the density scale).
float vol_density(vec3 p) {
  vec3 fl = floor(p);
  ivec3 v = ivec3(fl);
  ivec3 b = v >> 3;
  uint slot = vol_packed_slot(b);
  if (slot == 0u) return 0.0f;
  vec3 f = p - fl;
  ivec3 t = vol_slot_origin(slot) + (v - b * VOL_BRICK) + 1;
  float sum = 0.0f;
  for (int c = 0; c < 8; ++c) {
    ivec3 o = ivec3(c & 1, (c >> 1) & 1, (c >> 2) & 1);
    float w = (o.x != 0 ? f.x : 1.0f - f.x) * (o.y != 0 ? f.y : 1.0f - f.y) * (o.z != 0 ? f.z : 1.0f - f.z);
    sum += w * texelFetch(volAtlas, t + o, 0).r;
  }
  return sum;
}

float vol_sigma_t(vec3 indexPos) { return vol.boundsMin.w * vol_density(indexPos); }

// Per-brick majorant of sigma_t (level 0 of the hierarchy; the cell is relative to brickOrigin).
float vol_brick_majorant(ivec3 cell) {
  ivec3 dims = vol.levelDims[0].xyz;
  return vol.boundsMin.w * volMajorants[vol.levelOffset.x + uint((cell.z * dims.y + cell.y) * dims.x + cell.x)];
}

// The world ray mapped to index space; t stays in world units.
void vol_ray_to_index(vec3 oWorld, vec3 dWorld, out vec3 o, out vec3 d) {
  o = (vol.worldToIndex * vec4(oWorld, 1.0f)).xyz;
  d = (vol.worldToIndex * vec4(dWorld, 0.0f)).xyz;
}

bool vol_start(vec3 o, vec3 d, float tMax, out DdaState s) {
  if (vol.brickDims.w != 0) return false;  // empty volume
  return dda_init(s, o, d, 0.0f, tMax, vec3(vol.brickOrigin.xyz * VOL_BRICK), float(VOL_BRICK),
                  vol.levelDims[0].xyz);
}

// Delta tracking (Woodcock): the first real collision along the world ray in (0, tMax).
bool vol_sample_collision(vec3 oWorld, vec3 dWorld, float tMax, inout RngState rng, out float tHit) {
  tHit = tMax;
  vec3 o;
  vec3 d;
  vol_ray_to_index(oWorld, dWorld, o, d);
  DdaState s;
  if (!vol_start(o, d, tMax, s)) return false;
  uint steps = 0u;
  float a;
  float b;
  ivec3 cell;
  while (dda_next(s, a, b, cell)) {
    float maj = vol_brick_majorant(cell);
    if (maj <= 0.0f) continue;
    float t = a;  // exponential steps are memoryless: restart at the segment's entry
    for (;;) {
      if (++steps > VOL_MAX_STEPS) {
        atomicAdd(volCounters[0], 1u);
        return false;
      }
      vec2 u = rng_float2(rng);
      t -= log(1.0f - u.x) / maj;
      if (t >= b) break;
      if (u.y * maj < vol_sigma_t(o + t * d)) {
        tHit = t;
        return true;
      }
    }
  }
  return false;
}

// Ratio tracking: an unbiased estimate of the transmittance over (0, tMax).
float vol_ratio_tracking(vec3 oWorld, vec3 dWorld, float tMax, inout RngState rng) {
  vec3 o;
  vec3 d;
  vol_ray_to_index(oWorld, dWorld, o, d);
  DdaState s;
  if (!vol_start(o, d, tMax, s)) return 1.0f;
  uint steps = 0u;
  float tr = 1.0f;
  float a;
  float b;
  ivec3 cell;
  while (tr > 0.0f && dda_next(s, a, b, cell)) {
    float maj = vol_brick_majorant(cell);
    if (maj <= 0.0f) continue;
    float t = a;
    for (;;) {
      if (++steps > VOL_MAX_STEPS) {
        atomicAdd(volCounters[0], 1u);
        return tr;
      }
      t -= log(1.0f - rng_float(rng)) / maj;
      if (t >= b) break;
      tr *= max(0.0f, 1.0f - vol_sigma_t(o + t * d) / maj);
    }
  }
  return tr;
}

#endif
