// The bridge between the tracking algorithms and the baked volume: trilinear density with
// exact weights (8 texelFetch, DESIGN §3), per-brick majorants, delta tracking and ratio
// tracking over the majorant hierarchy. Mirrors media/bake_lookup.cpp texel for texel.
// Requires bindings.glsl.
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

// Majorant segments along a ray: [a, b) pieces with one sigma_t majorant each (possibly 0).
// Two implementations behind one interface (vol_segments_start / vol_segments_next):
//  - default: a DDA over the bricks (level 0 of the hierarchy);
//  - PLUME_SKIP_EMPTY: empty-space skipping over the hierarchy, an outer DDA over level-1 cells
//    (4³ bricks) that skips cells whose max is 0, and inside a non-empty one an inner DDA over
//    its bricks. It pays on large sparse volumes; on small ones its bookkeeping costs more than
//    it saves (measured on lavapipe: +35% on the bundled smoke), so the host picks the variant
//    from the size of the brick grid (render/path_tracer.cpp).
#ifdef PLUME_SKIP_EMPTY
struct VolSegments {
  DdaState outer;
  DdaState inner;
  ivec3 outerCell;
  bool innerLive;
  vec3 o;
  vec3 d;
};

float vol_level_max(int level, ivec3 cell) {
  ivec3 dims = vol.levelDims[level].xyz;
  return volMajorants[vol.levelOffset[level] + uint((cell.z * dims.y + cell.y) * dims.x + cell.x)];
}

bool vol_segments_start(out VolSegments w, vec3 o, vec3 d, float tMax) {
  w.o = o;
  w.d = d;
  w.outerCell = ivec3(0);
  w.innerLive = false;
  if (vol.brickDims.w != 0 || vol.info.x < 2u) return false;  // empty (or no level 1: host bug)
  vec3 origin = vec3(vol.brickOrigin.xyz * VOL_BRICK);
  return dda_init(w.outer, o, d, 0.0f, tMax, origin, float(VOL_BRICK * vol.levelDims[1].w), vol.levelDims[1].xyz);
}

bool vol_segments_next(inout VolSegments w, out float a, out float b, out float maj) {
  maj = 0.0f;
  for (;;) {
    ivec3 sub;
    if (w.innerLive) {
      if (dda_next(w.inner, a, b, sub)) {
        maj = vol_brick_majorant(w.outerCell * vol.levelDims[1].w + sub);
        return true;
      }
      w.innerLive = false;
    }
    ivec3 cell;
    if (!dda_next(w.outer, a, b, cell)) return false;
    if (vol_level_max(1, cell) <= 0.0f) continue;
    int n = vol.levelDims[1].w;  // bricks per level-1 cell edge
    w.outerCell = cell;
    ivec3 dims = min(ivec3(n), vol.levelDims[0].xyz - cell * n);
    vec3 origin = vec3((vol.brickOrigin.xyz + cell * n) * VOL_BRICK);
    w.innerLive = dda_init(w.inner, w.o, w.d, a, b, origin, float(VOL_BRICK), dims);
  }
  return false;
}
#else
#define VolSegments DdaState

bool vol_segments_start(out DdaState s, vec3 o, vec3 d, float tMax) {
  if (vol.brickDims.w != 0) return false;  // empty volume
  return dda_init(s, o, d, 0.0f, tMax, vec3(vol.brickOrigin.xyz * VOL_BRICK), float(VOL_BRICK),
                  vol.levelDims[0].xyz);
}

bool vol_segments_next(inout DdaState s, out float a, out float b, out float maj) {
  ivec3 cell;
  bool more = dda_next(s, a, b, cell);
  maj = more ? vol_brick_majorant(cell) : 0.0f;
  return more;
}
#endif

// Delta tracking (Woodcock): the first real collision along the world ray in (0, tMax).
bool vol_sample_collision(vec3 oWorld, vec3 dWorld, float tMax, inout RngState rng, out float tHit) {
  tHit = tMax;
  vec3 o;
  vec3 d;
  vol_ray_to_index(oWorld, dWorld, o, d);
  VolSegments walk;
  if (!vol_segments_start(walk, o, d, tMax)) return false;
  uint steps = 0u;
  float a;
  float b;
  float maj;
  while (vol_segments_next(walk, a, b, maj)) {
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

// Russian roulette on a transmittance estimate (unbiased): below VOL_RR_TRANSMITTANCE it
// survives with probability |T| / VOL_RR_TRANSMITTANCE and is raised to that value, so an
// estimate that can only add a little stops early instead of walking through the rest of a dense
// medium, and a survivor's weight stays bounded.
const float VOL_RR_TRANSMITTANCE = 0.01f;
bool vol_transmittance_roulette(inout float tr, inout RngState rng) {
  float m = abs(tr);
  if (!(m < VOL_RR_TRANSMITTANCE)) return true;
  if (rng_float(rng) * VOL_RR_TRANSMITTANCE >= m) return false;
  tr = tr < 0.0f ? -VOL_RR_TRANSMITTANCE : VOL_RR_TRANSMITTANCE;
  return true;
}

// Ratio tracking: an unbiased estimate of the transmittance over (0, tMax), with Russian
// roulette once it is small (vol_transmittance_roulette).
float vol_ratio_tracking(vec3 oWorld, vec3 dWorld, float tMax, inout RngState rng) {
  vec3 o;
  vec3 d;
  vol_ray_to_index(oWorld, dWorld, o, d);
  VolSegments walk;
  if (!vol_segments_start(walk, o, d, tMax)) return 1.0f;
  uint steps = 0u;
  float tr = 1.0f;
  float a;
  float b;
  float maj;
  while (tr > 0.0f && vol_segments_next(walk, a, b, maj)) {
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
      if (!vol_transmittance_roulette(tr, rng)) return 0.0f;
    }
  }
  return tr;
}

#endif
