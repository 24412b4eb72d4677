// The one majorant walk (in the spirit of pbrt-v4's SampleT_maj): a ray is cut into segments of
// a piecewise-constant field, and every tracker — delta tracking, ratio tracking, residual ratio
// tracking, the mean field's optical depth and sampling in it — is this one loop with its
// own "callbacks": what to do on entering a segment (vol_track_segment) and at each tentative
// collision of the Poisson process of rate mu it asks for there (vol_track_event). The tracker is
// a constant at every call site, so each inlined copy holds only its own code (a SIMD back end
// such as lavapipe runs both sides of an `if` otherwise: ../shared/docs/LAVAPIPE.md).
//
// Two fields:
//  - VOL_FIELD_MAJORANT: per-brick majorants of sigma_t, a DDA over the bricks; with
//    PLUME_SKIP_EMPTY an outer DDA over level-1 cells (4³ bricks) skips empty ones and an inner
//    DDA walks the bricks of the others (it pays on large sparse volumes; on small ones its
//    bookkeeping costs more than it saves, +35% on the bundled smoke with lavapipe, so the host
//    picks the variant from the size of the brick grid: render/path_tracer.cpp);
//  - VOL_FIELD_MEAN: ReSTIR's per-voxel mean field, an outer DDA over bricks (an empty brick is
//    one step) and an inner one over the voxels of each occupied brick, for its optical depth and
//    residual ratio tracking; a collision in it is sampled by delta tracking against the brick
//    majorants instead (VOL_TRACK_SAMPLE: no per-voxel walk). Where the fine density
//    strays far from a voxel's mean (its residual bound times the longest chord the ray can have
//    through the voxel exceeds VOL_EXACT_TAU optical depths) the field there is the fine
//    trilinear density itself, integrated exactly ("exact voxels", below): the ReSTIR field is
//    then a deterministic function of the voxel and the ray's direction, positive wherever the
//    fine density is, and close to it everywhere.
// Requires volume/bindings.glsl and volume/grid.glsl.
#ifndef PLUME_VOLUME_WALK_GLSL
#define PLUME_VOLUME_WALK_GLSL

#include "../shared/dda.h"
#include "../shared/rng.h"
#ifdef PLUME_KERNEL_COUNTERS
#include "counters.glsl"
#endif

const uint VOL_MAX_STEPS = 1u << 20;  // per tracking call; hits are counted in volCounters[0]
const float VOL_MAX_TAU = 80.0f;      // the mean field's optical depth is clamped here: exp(-80) > 0
// A mean-field voxel becomes exact when its residual bound (sigma_t units) times the longest chord
// of the ray's direction through a voxel exceeds this: the mean field's optical depth then differs
// from the fine one by at most this much per voxel elsewhere. (Measured on the 1e-30..1e30 grid
// and the bundled scenes: notes/extreme.md "Exact voxels".)
#ifndef PLUME_VOL_EXACT_TAU
#define PLUME_VOL_EXACT_TAU 0.5f
#endif

const uint VOL_FIELD_MAJORANT = 0u;
const uint VOL_FIELD_MEAN = 1u;

// --- Segments of a field along a ray ---------------------------------------------------------------
struct VolWalk {
  DdaState outer;
  DdaState inner;
  bool innerLive;
  uint v;
  ivec3 outerCell;
  uint base;   // VOL_FIELD_MEAN: the current brick's first mean-field word
  float scale; // VOL_FIELD_MEAN: the volume's density scale (read once, not per voxel)
  vec3 o;
  vec3 d;
  // VOL_FIELD_MEAN's exact voxels: the residual bound above which a voxel is exact for this
  // direction; the current brick's first voxel (index space) and first atlas texel; the last
  // exact voxel and its first corner texel.
  float exactBound;
  ivec3 brickVoxel;
  ivec3 brickTexel;
  ivec3 voxel;
  ivec3 texel;
};

// The part [t0, t1) of [0, tMax) inside the box [lo, hi] where the density may be non-zero (the
// active voxels grown by one: GpuVolume boundsMin/Max, index space); false where the ray misses
// it. The walks start there instead of at the brick grid's edge: they skip the margin bricks and
// the rays that only cross empty bricks (the bundled smoke's path tracer: DDA segments per pixel
// 5.6 -> 2.2, ~10% faster; notes/bench/kernels.md "Session 20").
bool vol_clip_to_bounds(vec3 lo, vec3 hi, vec3 o, vec3 d, float tMax, out float t0, out float t1) {
  vec3 inv = 1.0f / d;
  vec3 ta = (lo - o) * inv;
  vec3 tb = (hi - o) * inv;
  bvec3 still = equal(d, vec3(0.0f));
  bvec3 inside = bvec3(step(lo, o) * step(o, hi));
  vec3 flatNear = mix(vec3(DDA_INF), vec3(-DDA_INF), inside);
  vec3 tn = mix(min(ta, tb), flatNear, still);
  vec3 tf = mix(max(ta, tb), -flatNear, still);
  t0 = max(max(tn.x, tn.y), max(tn.z, 0.0f));
  t1 = min(min(tf.x, tf.y), min(tf.z, tMax));
  return t0 < t1;
}

// Whether a walk along the world ray (xWorld, wWorld) through the current volume may meet any
// density: false only where the ray misses the bounds of vol_clip_to_bounds grown by
// VOL_MEET_MARGIN index units (far above any rounding of the ray's transform in another
// kernel), so a ray it rejects is one every walk rejects. Lets a kernel cull rays before the
// walks' kernels (pt_camera).
const float VOL_MEET_MARGIN = 0.01f;
bool vol_may_meet(vec3 xWorld, vec3 wWorld) {
  vec3 o;
  vec3 d;
  vol_ray_to_index(VOL_CURRENT, xWorld, wWorld, o, d);
  float t0;
  float t1;
  return vol.empty == 0 && vol_clip_to_bounds(vol.boundsMin - VOL_MEET_MARGIN, vol.boundsMax + VOL_MEET_MARGIN, o, d,
                                               DDA_INF, t0, t1);
}

bool vol_walk_start(uint field, uint v, vec3 o, vec3 d, float tMax, out VolWalk w) {
  w.innerLive = false;
  w.v = v;
  w.outerCell = ivec3(0);
  w.base = 0u;
  w.scale = 0.0f;
  w.o = o;
  w.d = d;
  // The longest chord of direction d through a unit index cube is 1 / max_i |d_i| world units.
  w.exactBound = PLUME_VOL_EXACT_TAU * max(max(abs(d.x), abs(d.y)), abs(d.z));
  w.brickVoxel = ivec3(0);
  w.brickTexel = ivec3(0);
  w.voxel = ivec3(0);
  w.texel = ivec3(0);
  if (field == VOL_FIELD_MAJORANT) {
    float t0;
    float t1;
    if (vol.empty != 0 || !vol_clip_to_bounds(vol.boundsMin, vol.boundsMax, o, d, tMax, t0, t1)) return false;
#ifdef PLUME_SKIP_EMPTY
    if (vol.levelCount < 2u) return false;  // no level 1: a host bug
    dda_axes(w.inner, d, float(VOL_BRICK));  // the bricks under a level-1 cell: vol_walk_next
    return dda_init(w.outer, o, d, t0, t1, vec3(vol.brickOrigin * VOL_BRICK),
                    float(VOL_BRICK * vol.levels[1].bricksPerCell), vol.levels[1].cells);
#else
    return dda_init(w.outer, o, d, t0, t1, vec3(vol.brickOrigin * VOL_BRICK), float(VOL_BRICK),
                    vol.levels[0].cells);
#endif
  }
  // The mean field is 0 outside the bounds too (its voxels there have only zero corners).
  float t0;
  float t1;
  if (vol_is_empty(v) || !vol_clip_to_bounds(VOL_PARAM(v, boundsMin), VOL_PARAM(v, boundsMax), o, d, tMax, t0, t1))
    return false;
  w.scale = vol_scale(v);
  w.inner.dims = ivec3(VOL_BRICK);  // a brick's voxels: vol_mean_enter_brick
  dda_axes(w.inner, d, 1.0f);
  return dda_init(w.outer, o, d, t0, t1, vec3(VOL_PARAM(v, brickOrigin) * VOL_BRICK), float(VOL_BRICK),
                  VOL_PARAM(v, brickDims));
}

// The next segment [a, b) of the majorant field and its value there (sigma_t majorant, 0).
// Segments come in order; the field is 0 between them. (The mean field's walks have their own
// nested loops: vol_track_mean_closed, vol_track_mean_residual.)
bool vol_walk_next(inout VolWalk w, out float a, out float b, out vec2 value) {
  a = 0.0f;
  b = 0.0f;
  value = vec2(0.0f);
#ifndef PLUME_SKIP_EMPTY
  ivec3 cell;
  bool more = dda_next(w.outer, a, b, cell);
  value.x = more ? vol_brick_majorant(cell) : 0.0f;
  return more;
#else
  for (;;) {
    if (w.innerLive) {
      ivec3 sub;
      if (dda_next(w.inner, a, b, sub)) {
        value.x = vol_brick_majorant(w.outerCell * vol.levels[1].bricksPerCell + sub);
        return true;
      }
      w.innerLive = false;
    }
    float oa;
    float ob;
    ivec3 cell;
    if (!dda_next(w.outer, oa, ob, cell)) return false;
    if (vol_level_max(1, cell) <= 0.0f) continue;
    int n = vol.levels[1].bricksPerCell;
    w.outerCell = cell;
    w.inner.dims = min(ivec3(n), vol.levels[0].cells - cell * n);
    w.innerLive = dda_enter(w.inner, w.o, w.d, oa, ob, vec3((vol.brickOrigin + cell * n) * VOL_BRICK),
                            float(VOL_BRICK));
  }
  return false;
#endif
}

// --- Trackers ------------------------------------------------------------------------------------
const uint VOL_TRACK_DELTA = 0u;     // delta tracking (Woodcock): the first real collision
const uint VOL_TRACK_RATIO = 1u;     // ratio tracking: an unbiased transmittance estimate
const uint VOL_TRACK_RESIDUAL = 2u;  // residual ratio tracking against the mean field (unbiased)
const uint VOL_TRACK_TAU = 3u;       // the mean field's optical depth (deterministic)
const uint VOL_TRACK_SAMPLE = 4u;    // a collision in the mean field, by delta tracking in it
const uint VOL_TRACK_DELTA_EMIT = 5u;  // delta tracking that also gathers the medium's emission
const uint VOL_TRACK_RATIO_EMIT = 6u;  // the emission reaching the origin along a whole ray
const uint VOL_TRACK_RESIDUAL_RATIO = 7u;  // T_fine / T_mean by residual ratio tracking (unbiased)

struct VolTrack {
  float value;  // RATIO, RESIDUAL: the transmittance estimate; RESIDUAL_RATIO: that of its ratio
                // to the mean field's; TAU: the optical depth
  float t;      // DELTA, SAMPLE: the collision's distance (tMax without one)
  float sigma;  // SAMPLE: the mean field's sigma_t at the collision
  bool hit;     // DELTA, SAMPLE: a collision was found
  bool stop;    // the walk ends now (a hit, a transmittance ended by roulette, the step cap)
#ifdef PLUME_HAS_EMISSION
  vec3 emitted; // DELTA_EMIT: sum of sigma_t Le / mu over the tentative collisions up to the hit;
                // RATIO_EMIT: sum of T sigma_t Le / mu over all of them, T by ratio tracking
#endif
};

// Russian roulette on a transmittance estimate (unbiased): below VOL_RR_TRANSMITTANCE it
// survives with probability |T| / VOL_RR_TRANSMITTANCE and is raised to that value, so an
// estimate that can only add a little stops early instead of walking through the rest of a dense
// medium, and a survivor's weight stays bounded. 0.1, the CPU reference's threshold (session 3
// chose 0.01; session 20 measured 0.1 against it, two seeds, `plume bench` at 128²: the Blender
// fire's path tracer 9-13% faster per frame at the same or lower relMSE, the bundled smoke equal;
// next-event lookups per pixel had been 21% above the reference's; notes/bench/kernels.md).
// u: the tentative collision's own uniform (its second number, which ratio tracking's event does
// not otherwise read), independent of the optical depth that placed the collision and of the
// estimate so far; a draw of its own ran on every event of a SIMD back end's masked loop whether
// a lane needed it or not (the path tracer's shading ~10% faster without it, session 28).
const float VOL_RR_TRANSMITTANCE = 0.1f;
bool vol_transmittance_roulette(inout float tr, float u) {
  float m = abs(tr);
  if (!(m < VOL_RR_TRANSMITTANCE)) return true;
  if (u * VOL_RR_TRANSMITTANCE >= m) return false;
  tr = tr < 0.0f ? -VOL_RR_TRANSMITTANCE : VOL_RR_TRANSMITTANCE;
  return true;
}

#ifndef PLUME_RS_RESIDUAL_SCALE
#define PLUME_RS_RESIDUAL_SCALE 1.0f
#endif
// vol_residual_ratio's rate, in brick majorants: relative variance exp(int r² / (scale mu)) - 1
// for the residual r, at scale times the tentative collisions. Final shading's transmittances are
// a large part of ReSTIR's error: on the bundled smoke (128², `plume bench`, seeds 1-3) scale 1
// raised ReSTIR's relMSE ~30% over the per-voxel walk it replaced, 4 by 0-7% (shading ~1.5 ms a
// frame faster of 24: equal-time gains equal or better), 8 matched it at the walk's cost
// (notes/restir.md "Session 27").
#ifndef PLUME_RS_RATIO_SCALE
#define PLUME_RS_RATIO_SCALE 4.0f
#endif

// Whether the walk goes on to the next segment.
bool vol_track_alive(uint tracker, VolTrack s) {
  if (s.stop) return false;
  if (tracker == VOL_TRACK_RATIO || tracker == VOL_TRACK_RATIO_EMIT) return s.value > 0.0f;
  if (tracker == VOL_TRACK_RESIDUAL || tracker == VOL_TRACK_RESIDUAL_RATIO) return s.value != 0.0f;
  if (tracker == VOL_TRACK_TAU) return s.value < VOL_MAX_TAU;
  return !s.hit;
}

// On entering segment [a, b) with field value `value`: returns the rate of the tentative
// collisions the tracker wants there (0: none).
float vol_track_segment(uint tracker, inout VolTrack s, float a, float b, vec2 value) {
  if (tracker == VOL_TRACK_DELTA || tracker == VOL_TRACK_RATIO || tracker == VOL_TRACK_DELTA_EMIT ||
      tracker == VOL_TRACK_RATIO_EMIT || tracker == VOL_TRACK_SAMPLE) {
    return value.x;  // the majorant
  }
  if (tracker == VOL_TRACK_RESIDUAL_RATIO) return PLUME_RS_RATIO_SCALE * value.x;
  if (tracker == VOL_TRACK_RESIDUAL) {
    // The control's transmittance in closed form, the residual by ratio tracking at mu.
    s.value *= exp(-value.x * (b - a));
    return PLUME_RS_RESIDUAL_SCALE * value.y;
  }
  s.value += value.x * (b - a);  // VOL_TRACK_TAU
  return 0.0f;
}

#if defined(PLUME_VOL_MEAN_FIELD) || defined(PLUME_VOL_PREVIOUS)
// --- Exact voxels of the mean field ----------------------------------------------------------------
// Inside one voxel the fine density is one trilinear polynomial of its 8 corner texels (the
// voxel of vol_locate), so along a segment it is a cubic in the segment's parameter u in [0, 1]:
// two-point Gauss-Legendre integrates it exactly. (Collisions in the field are sampled by delta
// tracking, which reads the density at a point: vol_fine_and_mean.)
struct VolExact {
  float c[8];  // corner texels, vol_corner_weight's order
  vec3 fa;     // fractions in the voxel at the segment's start
  vec3 df;     // their change over the segment
};

VolExact vol_exact_start(VolWalk w, float a, float b) {
  VolExact e;
  for (int k = 0; k < 8; ++k) e.c[k] = vol_texel(w.v, w.texel + ivec3(k & 1, (k >> 1) & 1, k >> 2));
  vec3 base = vec3(w.voxel);
  e.fa = w.o + a * w.d - base;
  e.df = (w.o + b * w.d - base) - e.fa;
  return e;
}

// The density at parameter u of the segment (not yet multiplied by the density scale).
float vol_exact_density(VolExact e, float u) {
  vec3 f = clamp(e.fa + u * e.df, vec3(0.0f), vec3(1.0f));
  float sum = 0.0f;
  for (int c = 0; c < 8; ++c) sum += vol_corner_weight(c, f) * e.c[c];
  return sum;
}

// Its integral over (0, u).
float vol_exact_integral(VolExact e, float u) {
  float h = 0.5f * u;
  float g = 0.57735026918962576f * h;  // h / sqrt(3)
  return h * (vol_exact_density(e, h - g) + vol_exact_density(e, h + g));
}

// vol_track_segment for an exact voxel: TAU adds, RESIDUAL multiplies by the exact transmittance
// (the residual is 0: no tentative collisions).
float vol_track_exact(uint tracker, inout VolTrack s, VolWalk w, float scale, float a, float b) {
  VolExact e = vol_exact_start(w, a, b);
  float total = scale * (b - a) * vol_exact_integral(e, 1.0f);
  if (tracker == VOL_TRACK_RESIDUAL) {
    s.value *= exp(-total);
  } else {
    s.value += total;  // VOL_TRACK_TAU
  }
  return 0.0f;
}

// sigma_t at index-space point p of volume v: the fine density's (x) and the mean field's (y), for
// a ray whose voxels are exact above the residual bound exactBound (VolWalk.exactBound): the
// voxel's mean, or in an exact voxel the fine density. One indirection read serves both (a SIMD
// back end such as lavapipe reads the fine density for every lane anyway: both sides of the
// exact voxel's select run). The brick majorants bound both (media/bake.cpp raises a brick's
// majorant to its voxels' largest mean where rounding put a mean above it), so delta tracking
// against them samples the mean field's collisions (VOL_TRACK_SAMPLE).
vec2 vol_fine_and_mean(uint v, float scale, vec3 p, float exactBound) {
  uint slot;
  ivec3 sub;
  ivec3 t;
  vec3 f;
  if (!vol_locate_voxel(v, p, slot, sub, t, f)) return vec2(0.0f);
  float fine = scale * vol_density_at(v, t, f);
  vec2 m = scale * vol_mean_field(v, vol_mean_field_index(v, slot, sub));
  return vec2(fine, m.y > exactBound ? fine : m.x);
}
#endif

// At a tentative collision at distance t (index-space point p) of rate mu, in a segment of field
// value `value`, in volume v of density scale `scale`; u is a uniform number drawn with the step;
// exactBound: the walk's (VolWalk.exactBound, for SAMPLE).
void vol_track_event(uint tracker, inout VolTrack s, uint v, float scale, vec3 p, float t, float mu, vec2 value,
                     float u, float exactBound) {
  if (tracker == VOL_TRACK_DELTA) {
    if (u * mu < scale * vol_density(v, p)) {
      s.t = t;
      s.hit = true;
      s.stop = true;
    }
  } else if (tracker == VOL_TRACK_RATIO) {
    s.value *= max(0.0f, 1.0f - scale * vol_density(v, p) / mu);
    if (!vol_transmittance_roulette(s.value, u)) {
      s.value = 0.0f;
      s.stop = true;
    }
  } else if (tracker == VOL_TRACK_RESIDUAL) {
    s.value *= 1.0f - (scale * vol_density(v, p) - value.x) / mu;
  }
#if defined(PLUME_VOL_MEAN_FIELD) || defined(PLUME_VOL_PREVIOUS)
  else if (tracker == VOL_TRACK_SAMPLE) {
    float sigma = vol_fine_and_mean(v, scale, p, exactBound).y;
    if (u * mu < sigma) {
      s.t = t;
      s.sigma = sigma;
      s.hit = true;
      s.stop = true;
    }
  } else if (tracker == VOL_TRACK_RESIDUAL_RATIO) {
    // The fine density and the mean field both lie in [0, mu / PLUME_RS_RATIO_SCALE]: the factor
    // in [1 - 1 / scale, 1 + 1 / scale], [0.75, 1.25] at the default 4.
    vec2 sigma = vol_fine_and_mean(v, scale, p, exactBound);
    s.value *= 1.0f - (sigma.x - sigma.y) / mu;
  }
#endif
#ifdef PLUME_HAS_EMISSION
  else if (tracker == VOL_TRACK_DELTA_EMIT) {
    // Every tentative collision, the one that turns out real included, adds sigma_t Le / mu: a
    // point of the majorant's Poisson process is reached with probability T(t) (delta tracking's
    // survival is the transmittance), so the sum estimates the integral of T sigma_t Le up to the
    // collision (pbrt-v4's emission at majorant events); times 1 - albedo it is sigma_a Le.
    float sigma = scale * vol_density(v, p);
    s.emitted += (sigma / mu) * vol_emitted_radiance(v, p);
    if (u * mu < sigma) {
      s.t = t;
      s.hit = true;
      s.stop = true;
    }
  } else if (tracker == VOL_TRACK_RATIO_EMIT) {
    // Every tentative collision adds T(t) sigma_t Le / mu with T(t) the ratio-tracking estimate up
    // to it (unbiased for the transmittance there, and independent of the point's own weight), so
    // the sum estimates the integral of T sigma_t Le over the whole ray without stopping at a
    // collision: the expected-value form of DELTA_EMIT, for rays that need no collision.
    float sigma = scale * vol_density(v, p);
    s.emitted += (s.value * sigma / mu) * vol_emitted_radiance(v, p);
    s.value *= max(0.0f, 1.0f - sigma / mu);
    if (!vol_transmittance_roulette(s.value, u)) {
      s.value = 0.0f;
      s.stop = true;
    }
  }
#endif
}

#ifdef PLUME_KERNEL_COUNTERS
#define VOL_KC_PARAM , inout VolKc kc
#define VOL_KC_ARG , kc
#else
#define VOL_KC_PARAM
#define VOL_KC_ARG
#endif

// One draw of the next tentative collision: h (h.y: the event's u) and the optical depth tau ~
// Exp(1) to it; false where the step cap ends the walk (s.stop).
bool vol_draw_depth(inout VolTrack s, inout uint steps, inout RngWalk g, out uvec2 h, out float tau VOL_KC_PARAM) {
  h = uvec2(0u);
  tau = 0.0f;
  if (++steps > VOL_MAX_STEPS) {
    s.stop = true;
    return false;
  }
#ifdef PLUME_KERNEL_COUNTERS
  vol_kc_step(kc);
#endif
  h.x = rng_walk_next(g);
  h.y = rng_walk_next(g);
  tau = -log(1.0f - rng_to_float(h.x));
  return true;
}

// The walk's loops. A SIMD back end runs a loop's whole body on every iteration while any lane
// needs it (../shared/docs/LAVAPIPE.md), so which code shares a loop matters. The majorant field
// (delta and ratio tracking) is walked by collision: the outer loop draws one tentative
// collision's optical depth and makes its density lookup; the inner loop spends that depth
// across the majorant's segments and holds neither a draw nor a lookup. Each runs once per
// tentative collision of the subgroup (the lookup in the outer loop: path tracer extension 11 %
// faster, session 13). Until session 21 the inner loop also drew anew at each segment's entry
// (a draw per segment crossed as well, and both kinds of work in every iteration): one draw per
// collision made the bundled smoke's path tracer ~1.5x faster per sample and raised its lanes in
// the tracking loop from 3.0 to 4.1 of 8 (notes/bench/kernels.md "Session 21"). The mean field:
// below.
void vol_track_by_collision(uint tracker, uint v, inout VolTrack s, inout VolWalk w, float scale, vec3 o,
                            vec3 d, inout uint steps, inout RngWalk g VOL_KC_PARAM) {
  float a = 0.0f;
  float b = 0.0f;  // the current segment [a, b) (none yet: the first is entered below)
  vec2 value = vec2(0.0f);
  float mu = 0.0f;
  float t = 0.0f;
  for (;;) {
    // The next tentative collision: an optical depth tau ~ Exp(1) of the process of rate mu from
    // t on, spent across segments (one draw per tentative collision, not one per segment as well).
    uvec2 h;
    float tau;
    if (!vol_draw_depth(s, steps, g, h, tau VOL_KC_ARG)) break;
    bool found = false;
    for (;;) {
      float left = mu * (b - t);  // the optical depth left in the current segment
      if (tau < left) {
        t += tau / mu;
        found = true;
        break;
      }
      tau -= left;
      // A segment is entered only where the tracker still needs one.
      if (!vol_track_alive(tracker, s) || !vol_walk_next(w, a, b, value)) break;
#ifdef PLUME_KERNEL_COUNTERS
      vol_kc_segment(kc);
#endif
      mu = vol_track_segment(tracker, s, a, b, value);
      t = a;
    }
    if (!found) break;
#ifdef PLUME_KERNEL_COUNTERS
    vol_kc_lookup(kc);
#endif
    vol_track_event(tracker, s, v, scale, o + t * d, t, mu, value, rng_to_float(h.y), w.exactBound);
    if (s.stop) break;
  }
}

#if defined(PLUME_VOL_MEAN_FIELD) || defined(PLUME_VOL_PREVIOUS)
// The mean field's walks, in nested loops: the voxel loop holds only a mean-field read, the
// tracker's closed form for the voxel and, for RESIDUAL, the draws of its tentative collisions;
// it leaves for the rare work, which the loops around it do: a new brick (the indirection read
// and the voxel DDA's set-up; empty bricks in their own tight loop) and a tentative collision's
// density lookup in the brick loop, an exact voxel (8 texel reads, Gauss-Legendre) in the
// outermost loop, the rarest. As one loop over segments
// (vol_walk_next), every voxel paid for all three on lavapipe: ReSTIR's candidates ran 3.7x and
// its spatial reuse 2.2x slower (notes/bench/kernels.md, "Session 14"). The same segments in the
// same order, so the same results to the bit.

// Steps w.outer to the next occupied brick and sets w.inner up over its voxels; false past the
// last one.
bool vol_mean_enter_brick(inout VolWalk w) {
  for (;;) {
    float oa;
    float ob;
    ivec3 cell;
    uint slot = 0u;
    bool more;
    for (;;) {
      more = dda_next(w.outer, oa, ob, cell);
      if (!more) break;
      slot = vol_packed_slot(w.v, VOL_PARAM(w.v, brickOrigin) + cell);
      if (slot != 0u) break;
    }
    if (!more) return false;
    ivec3 brick = VOL_PARAM(w.v, brickOrigin) + cell;
    w.base = vol_mean_field_base(w.v, slot);
    w.brickVoxel = brick * VOL_BRICK;
    w.brickTexel = vol_slot_coords(slot) * VOL_TEXELS + 1;  // as vol_locate
    if (dda_enter(w.inner, w.o, w.d, oa, ob, vec3(brick * VOL_BRICK), 1.0f)) return true;
  }
  return false;
}

// The next voxel [a, b) of the current brick and its value (sigma_t of the mean, sigma_t bound of
// the residual); `exact`: the voxel is exact for this direction (w.voxel, w.texel then locate it).
bool vol_mean_next_voxel(inout VolWalk w, out float a, out float b, out vec2 value, out bool exact) {
  ivec3 sub;
  value = vec2(0.0f);
  exact = false;
  if (!dda_next(w.inner, a, b, sub)) return false;
  value = w.scale * vol_mean_field(w.v, w.base + uint((sub.z * VOL_BRICK + sub.y) * VOL_BRICK + sub.x));
  exact = value.y > w.exactBound;
  if (exact) {
    w.voxel = w.brickVoxel + sub;
    w.texel = w.brickTexel + sub;
  }
  return true;
}

// The closed-form tracker (TAU: no draws). An exact voxel leaves both loops for the outermost
// one, which integrates it: a SIMD back end runs that loop's body once per walk and exact voxel
// met by any lane, instead of once per brick entered (in the brick loop every brick paid the
// exact voxel's 8 texel reads, masked, ~12% of a ReSTIR iteration on the bundled smoke: a perf
// profile, notes/bench/kernels.md "Session 29"). The same segments in the same order, so the
// same bits.
void vol_track_mean_closed(uint tracker, inout VolTrack s, inout VolWalk w, float scale VOL_KC_PARAM) {
  bool innerLive = false;
  float a = 0.0f;
  float b = 0.0f;
  for (;;) {
    bool pending = false;  // an exact voxel [a, b) waits for this loop
    for (;;) {
      if (!innerLive) {
        if (!vol_mean_enter_brick(w)) break;
        innerLive = true;
      }
      for (;;) {
        vec2 value;
        if (!vol_mean_next_voxel(w, a, b, value, pending)) {
          innerLive = false;
          break;
        }
#ifdef PLUME_KERNEL_COUNTERS
        vol_kc_segment(kc);
#endif
        if (pending) break;
        vol_track_segment(tracker, s, a, b, value);
        if (!vol_track_alive(tracker, s)) break;
      }
      if (pending || !vol_track_alive(tracker, s)) break;
    }
    if (!pending) break;
    vol_track_exact(tracker, s, w, scale, a, b);
    if (!vol_track_alive(tracker, s)) break;
  }
}

// Residual ratio tracking: the voxel loop spends the optical depth to the next tentative
// collision of the residual's process (drawn in the outer loop, as vol_track_by_collision's) and
// leaves at one.
const uint VOL_PENDING_NONE = 0u;
const uint VOL_PENDING_EXACT = 1u;  // an exact voxel over [a, b)
const uint VOL_PENDING_EVENT = 2u;  // a tentative collision at t
void vol_track_mean_residual(uint tracker, uint v, inout VolTrack s, inout VolWalk w, float scale, vec3 o, vec3 d,
                             inout uint steps, inout RngWalk g VOL_KC_PARAM) {
  bool innerLive = false;
  uint pending = VOL_PENDING_NONE;
  bool draw = true;  // the next tentative collision's optical depth is to be drawn
  float a = 0.0f;
  float b = 0.0f;
  vec2 value = vec2(0.0f);
  float mu = 0.0f;   // the residual's rate in [a, b)
  float t = 0.0f;    // [t, b) is what is left of the current voxel
  float tau = 0.0f;  // the optical depth to the next tentative collision
  uvec2 h = uvec2(0u);
  // Exact voxels in the outermost loop, as vol_track_mean_closed's; tentative collisions and
  // bricks in the middle one.
  for (;;) {
    for (;;) {
      if (pending == VOL_PENDING_EVENT) {
#ifdef PLUME_KERNEL_COUNTERS
        vol_kc_lookup(kc);
#endif
        vol_track_event(tracker, s, v, scale, o + t * d, t, mu, value, rng_to_float(h.y), w.exactBound);
        if (s.stop) break;
        draw = true;
      }
      pending = VOL_PENDING_NONE;
      if (draw) {
        if (!vol_draw_depth(s, steps, g, h, tau VOL_KC_ARG)) break;
        draw = false;
      }
      if (!vol_track_alive(tracker, s)) break;
      if (!innerLive) {
        if (!vol_mean_enter_brick(w)) break;
        innerLive = true;
      }
      for (;;) {
        float left = mu * (b - t);
        if (tau < left) {
          t += tau / mu;
          pending = VOL_PENDING_EVENT;
          break;
        }
        tau -= left;
        t = b;
        bool exact;
        if (!vol_track_alive(tracker, s)) break;
        if (!vol_mean_next_voxel(w, a, b, value, exact)) {
          innerLive = false;
          break;
        }
#ifdef PLUME_KERNEL_COUNTERS
        vol_kc_segment(kc);
#endif
        if (exact) {
          mu = 0.0f;
          t = b;
          pending = VOL_PENDING_EXACT;
          break;
        }
        mu = vol_track_segment(tracker, s, a, b, value);
        t = a;
      }
      if (pending == VOL_PENDING_EXACT) break;
      if (pending == VOL_PENDING_NONE && (innerLive || !vol_track_alive(tracker, s))) break;
    }
    if (pending != VOL_PENDING_EXACT) break;
    vol_track_exact(tracker, s, w, scale, a, b);  // the residual is 0 there: tau carries over
    pending = VOL_PENDING_NONE;
  }
}
#endif

// The walk. `init`: the tracker's starting value (RATIO, RESIDUAL, RESIDUAL_RATIO 1; TAU 0;
// DELTA, SAMPLE unused). A walk that draws takes one rng_next4 of the stream as the state of its
// own generator (rng_walk_init, shared/rng.h: xoshiro128+, a few shifts and xors per number
// instead of a pcg4d's chain of multiplies; the bundled smoke's path tracer ~10% faster, its
// shading kernel ~18%); each tentative collision of the majorant's (or the residual's) Poisson
// process takes two numbers of it: the optical depth Exp(1) to it from the last one, spent across
// segments of different rates (the inverse of the piecewise-linear optical depth), and the
// event's u (ratio tracking's roulette reads it: vol_transmittance_roulette).
VolTrack vol_track(uint tracker, uint v, vec3 xWorld, vec3 wWorld, float tMax, float init, inout RngState rng) {
  VolTrack s;
  s.value = init;
  s.t = tMax;
  s.sigma = 0.0f;
  s.hit = false;
  s.stop = false;
#ifdef PLUME_HAS_EMISSION
  s.emitted = vec3(0.0f);
#endif
  uint field = (tracker == VOL_TRACK_RESIDUAL || tracker == VOL_TRACK_TAU) ? VOL_FIELD_MEAN : VOL_FIELD_MAJORANT;
  vec3 o;
  vec3 d;
  vol_ray_to_index(v, xWorld, wWorld, o, d);
  VolWalk w;
  if (!vol_walk_start(field, v, o, d, tMax, w)) return s;
  uint steps = 0u;
#ifdef PLUME_KERNEL_COUNTERS
  VolKc kc = vol_kc_start();
#endif
  float scale = vol_scale(v);  // sigma_t = scale * d, read once per walk
  // The walk's own generator, one draw of the stream (the mean field's optical depth draws none).
  RngWalk g;
  g.s = uvec4(0u);
  if (tracker != VOL_TRACK_TAU) g = rng_walk_init(rng);
  if (field == VOL_FIELD_MAJORANT) {
    vol_track_by_collision(tracker, v, s, w, scale, o, d, steps, g VOL_KC_ARG);
  } else {
#if defined(PLUME_VOL_MEAN_FIELD) || defined(PLUME_VOL_PREVIOUS)
    if (tracker == VOL_TRACK_RESIDUAL) {
      vol_track_mean_residual(tracker, v, s, w, scale, o, d, steps, g VOL_KC_ARG);
    } else {
      vol_track_mean_closed(tracker, s, w, scale VOL_KC_ARG);
    }
#endif
  }
  if (steps > VOL_MAX_STEPS) atomicAdd(volCounters[0], 1u);  // truncated: counted, never silent
#ifdef PLUME_KERNEL_COUNTERS
  vol_kc_flush(tracker, kc, min(steps, VOL_MAX_STEPS));
#endif
  return s;
}

// --- The trackers by name ------------------------------------------------------------------------
// Delta tracking: the first real collision along the world ray in (0, tMax).
bool vol_sample_collision(vec3 oWorld, vec3 dWorld, float tMax, inout RngState rng, out float tHit) {
  VolTrack s = vol_track(VOL_TRACK_DELTA, VOL_CURRENT, oWorld, dWorld, tMax, 0.0f, rng);
  tHit = s.t;
  return s.hit;
}

#ifdef PLUME_HAS_EMISSION
// Delta tracking as vol_sample_collision, and the radiance the medium emits towards the ray's
// origin up to the collision (or tMax), divided by the albedo's complement: `emitted` times
// (1 - albedo) is an unbiased estimate of the integral of T sigma_a Le.
bool vol_sample_collision_emitting(vec3 oWorld, vec3 dWorld, float tMax, inout RngState rng, out float tHit,
                                   out vec3 emitted) {
  VolTrack s = vol_track(VOL_TRACK_DELTA_EMIT, VOL_CURRENT, oWorld, dWorld, tMax, 0.0f, rng);
  tHit = s.t;
  emitted = s.emitted;
  return s.hit;
}
#endif

#ifdef PLUME_HAS_EMISSION
// The radiance the medium emits towards the ray's origin over (0, tMax), divided by the albedo's
// complement (times 1 - albedo: an unbiased estimate of the integral of T sigma_a Le): ratio
// tracking's running transmittance weighs every tentative collision (VOL_TRACK_RATIO_EMIT).
vec3 vol_emission_along(vec3 oWorld, vec3 dWorld, float tMax, inout RngState rng) {
  return vol_track(VOL_TRACK_RATIO_EMIT, VOL_CURRENT, oWorld, dWorld, tMax, 1.0f, rng).emitted;
}
#endif

// Ratio tracking: an unbiased estimate of the transmittance over (0, tMax), with Russian
// roulette once it is small (vol_transmittance_roulette).
float vol_ratio_tracking(vec3 oWorld, vec3 dWorld, float tMax, inout RngState rng) {
  return vol_track(VOL_TRACK_RATIO, VOL_CURRENT, oWorld, dWorld, tMax, 1.0f, rng).value;
}

#if defined(PLUME_VOL_MEAN_FIELD) || defined(PLUME_VOL_PREVIOUS)
// Optical depth of the mean field over (0, tMax) along a world ray in volume v (deterministic;
// approximates the fine optical depth, not a bound; stops once past VOL_MAX_TAU).
float vol_mean_tau(uint v, vec3 xWorld, vec3 wWorld, float tMax) {
  RngState unused = RngState(uvec4(0u), 0u);  // never drawn from: TAU asks for no collisions
  return vol_track(VOL_TRACK_TAU, v, xWorld, wWorld, tMax, 0.0f, unused).value;
}

// The optical depth of volume v's mean field over (0, tMax) by the midpoint rule: steps of about
// one voxel, each reading the mean of the voxel its midpoint lies in (two texel reads: the brick's
// slot, the voxel's mean), no DDA. A deterministic function of the ray, so ReSTIR's target may
// use it for its light rays (restir/bridge.glsl rs_light_term): the target only has to be the
// same function in every domain, and final shading estimates the light's transmittance without
// bias. But a target far darker than the light that arrives turns that light into rare, huge
// contributions, so an exact voxel (its mean strays from the density by more than the chord
// allows: vol_walk_start's exactBound) whose residual bound exceeds twice its mean, where a few
// corners hold the density and the mean says nothing about a chord's share of it, counts as empty:
// the target errs on the bright side there (with the voxel's mean the 1e-30..1e30 grid read 2.8%
// dark at the extreme suite's sample count). Measured alternatives: every exact voxel at its
// density's lower bound (mean - residual) made the target too bright in real smoke (the Blender
// smoke's relMSE +32%); the trilinear density at exact midpoints, or vol_mean_tau's walk for rays
// that meet one, cost as much as the rule saves (lavapipe runs them masked on every step or ray).
// Against the walk it reads the smoke's shadow slightly less exactly for far less work
// (notes/restir.md "Light rays of the target by the midpoint rule").
float vol_mean_tau_midpoints(uint v, vec3 xWorld, vec3 wWorld, float tMax) {
  if (vol_is_empty(v)) return 0.0f;
  vec3 o;
  vec3 d;
  vol_ray_to_index(v, xWorld, wWorld, o, d);
  // The ray's part inside the box where the field may be non-zero (index space; t in world units
  // along wWorld; the mean field's voxels outside it have only zero corners).
  float t0;
  float t1;
  if (!vol_clip_to_bounds(VOL_PARAM(v, boundsMin), VOL_PARAM(v, boundsMax), o, d, tMax, t0, t1)) return 0.0f;
  uint n = max(1u, uint(ceil((t1 - t0) * length(d))));  // steps of at most one voxel
  float h = (t1 - t0) / float(n);
  float sum = 0.0f;
  float enough = VOL_MAX_TAU / (vol_scale(v) * h);  // the transmittance's floor is reached
  // A voxel is exact for this direction where scale * residual bound > PLUME_VOL_EXACT_TAU times
  // the longest chord through it (as vol_walk_start, in density units).
  float exactResidual = PLUME_VOL_EXACT_TAU * max(max(abs(d.x), abs(d.y)), abs(d.z)) / vol_scale(v);
  for (uint k = 0u; k < n && !(sum > enough); ++k) {
    ivec3 voxel = ivec3(floor(o + (t0 + (float(k) + 0.5f) * h) * d));
    ivec3 brick = ivec3(floor(vec3(voxel) * (1.0f / float(VOL_BRICK))));
    ivec3 sub = clamp(voxel - brick * VOL_BRICK, ivec3(0), ivec3(VOL_BRICK - 1));
    uint slot = vol_packed_slot(v, brick);
    uint at = slot != 0u ? vol_mean_field_index(v, slot, sub) : 0u;
    vec2 m = slot != 0u ? vol_mean_field(v, at) : vec2(0.0f);
    sum += m.y > exactResidual && m.y > 2.0f * m.x ? 0.0f : m.x;
  }
  return vol_scale(v) * sum * h;
}

// The cheap deterministic strictly positive transmittance of ReSTIR's target function.
float vol_mean_tr(uint v, vec3 xWorld, vec3 wWorld, float tMax) {
  return exp(-min(vol_mean_tau(v, xWorld, wWorld, tMax), VOL_MAX_TAU));
}

// A collision in the current volume's mean field (vol_fine_and_mean) by delta tracking against the
// brick majorants: its distance t has the free-flight pdf sigmaC exp(-tau_c(0, t)), sigmaC the
// field at the collision (returned), and there is none (false) with probability
// exp(-tau_c(0, tMax)). The optical depth tau_c itself is not known here, and ReSTIR's candidates
// need none: the target's transmittance of the segment is the same exp(-tau_c) (vol_mean_tr), so
// it cancels in a candidate's weight f / p, which keeps sigma / sigmaC (restir/candidates.glsl).
// Against walking the field voxel by voxel in closed form (until session 27), a few tentative
// collisions a brick instead of every voxel crossed (notes/bench/kernels.md "Session 27").
bool vol_mean_sample(vec3 xWorld, vec3 wWorld, float tMax, inout RngState rng, out float t, out float sigmaC) {
  VolTrack s = vol_track(VOL_TRACK_SAMPLE, VOL_CURRENT, xWorld, wWorld, tMax, 0.0f, rng);
  t = s.t;
  sigmaC = s.sigma;
  return s.hit;
}

// Unbiased transmittance on the current volume's fine grid by residual ratio tracking (Novák et
// al. 2014) with the mean field as control: T = exp(-tau_mean) * prod_i (1 - (sigma(x_i) -
// sigma_mean(x_i)) / mu), the points x_i a Poisson process of rate mu = PLUME_RS_RESIDUAL_SCALE
// times the cell's residual majorant. Its ratio to the target's exp(-tau_mean) is the product
// alone, with relative variance exp(int r² / mu) - 1 for the residual r: final shading's f / p̂
// stays near 1 where the mean field is close to the fine one, at a cost proportional to the
// residual's optical depth instead of the density's.
float vol_residual_tr(vec3 xWorld, vec3 wWorld, float tMax, inout RngState rng) {
  return vol_track(VOL_TRACK_RESIDUAL, VOL_CURRENT, xWorld, wWorld, tMax, 1.0f, rng).value;
}

// An unbiased estimate of the ratio T / exp(-tau_c) of the current volume's fine transmittance
// over (0, tMax) to its mean field's (vol_fine_and_mean), without walking the mean field: residual
// ratio tracking's product alone, prod_i (1 - (sigma(x_i) - sigma_c(x_i)) / mu) over a Poisson
// process of rate mu = PLUME_RS_RATIO_SCALE brick majorants, whose expectation is
// exp(-int (sigma - sigma_c)). Where a caller knows exp(-tau_c) already (final shading: it is part of the reservoir's p̂,
// restir/shade.glsl), this is all the unbiased transmittance needs: a few tentative collisions a
// brick instead of every voxel crossed. Relative variance exp(int (sigma - sigma_c)² / mu) - 1.
float vol_residual_ratio(vec3 xWorld, vec3 wWorld, float tMax, inout RngState rng) {
  return vol_track(VOL_TRACK_RESIDUAL_RATIO, VOL_CURRENT, xWorld, wWorld, tMax, 1.0f, rng).value;
}
#endif

#endif
