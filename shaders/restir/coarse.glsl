// Volume lookups for ReSTIR's target function and candidates, for the current (v = 0) or the
// previous frame's (v = 1) bake: fine trilinear density (the same arithmetic as
// volume/volume.glsl's vol_density) and, on single voxels, the piecewise-constant field of the
// voxel means of the trilinear density (bake.voxelMean) and a bound on the fine density's
// deviation from it (bake.voxelResidual). The mean field is what candidates track, what the
// target's transmittance integrates and the control of final shading's residual ratio tracking.
// It is positive wherever the fine density is (a voxel's mean weighs all its corners
// positively), so candidates cover the target's support without the dilated field of DESIGN §3:
// tracking the dilated field made the weights p̂ / p grow like exp(tau_dilated - tau_mean) with
// depth, and those rare huge weights, kept by temporal reuse, were most of the error. Voxel
// cells rather than 2³-voxel ones bring p̂ closer to f: relMSE -35% on the bundled smoke for
// 10-20% more time (notes/restir.md).
// Coarse tracking: in a piecewise-constant medium the majorant equals the density, so every
// tentative collision is real and the free-flight pdf is sigma_c(t) exp(-tau_c(0, t)) in closed
// form, with tau_c the exact optical depth of the coarse field, summed cell by cell with a DDA.
// Requires restir/bindings.glsl.
#ifndef PLUME_RESTIR_COARSE_GLSL
#define PLUME_RESTIR_COARSE_GLSL

#include "../shared/dda.h"

// Cells: single voxels, 8³ per brick. The buffer holds, per atlas slot, the 512 voxel means then
// their 512 residual bounds (render/gpu_volume.cpp).
const float RS_MAX_TAU = 80.0f;      // exp(-80) > 0 in float: p̂ stays strictly positive

float rsv_scale(uint v) { return v == 0u ? vol.boundsMin.w : prevVol.boundsMin.w; }
bool rsv_empty(uint v) { return (v == 0u ? vol.brickDims.w : prevVol.brickDims.w) != 0; }

void rsv_ray_to_index(uint v, vec3 oWorld, vec3 dWorld, out vec3 o, out vec3 d) {
  mat4 m = v == 0u ? vol.worldToIndex : prevVol.worldToIndex;
  o = (m * vec4(oWorld, 1.0f)).xyz;
  d = (m * vec4(dWorld, 0.0f)).xyz;
}

// Packed slot coordinates of a brick (0: empty), as vol_packed_slot.
uint rsv_packed_slot(uint v, ivec3 brick) {
  ivec3 origin = v == 0u ? vol.brickOrigin.xyz : prevVol.brickOrigin.xyz;
  ivec3 dims = v == 0u ? vol.brickDims.xyz : prevVol.brickDims.xyz;
  ivec3 r = brick - origin;
  if (any(lessThan(r, ivec3(0))) || any(greaterThanEqual(r, dims))) return 0u;
  uint i = uint((r.z * dims.y + r.y) * dims.x + r.x);
  return v == 0u ? volIndirection[i] : prevIndirection[i];
}

// Fine density d at an index-space point (exact trilinear weights, 8 fetches).
float rsv_density(uint v, vec3 p) {
  vec3 fl = floor(p);
  ivec3 vox = ivec3(fl);
  ivec3 b = vox >> 3;
  uint slot = rsv_packed_slot(v, b);
  if (slot == 0u) return 0.0f;
  vec3 f = p - fl;
  ivec3 t = ivec3(int(slot & 1023u), int((slot >> 10u) & 1023u), int(slot >> 20u)) * 10 + (vox - b * 8) + 1;
  float sum = 0.0f;
  for (int c = 0; c < 8; ++c) {
    ivec3 o = ivec3(c & 1, (c >> 1) & 1, (c >> 2) & 1);
    float w = (o.x != 0 ? f.x : 1.0f - f.x) * (o.y != 0 ? f.y : 1.0f - f.y) * (o.z != 0 ? f.z : 1.0f - f.z);
    sum += w * (v == 0u ? texelFetch(volAtlas, t + o, 0).r : texelFetch(prevAtlas, t + o, 0).r);
  }
  return sum;
}

// sigma_t at a world point.
float rsv_sigma_t(uint v, vec3 xWorld) {
  if (rsv_empty(v)) return 0.0f;
  vec3 o;
  vec3 d;
  rsv_ray_to_index(v, xWorld, vec3(0.0f), o, d);
  return rsv_scale(v) * rsv_density(v, o);
}

// A walk along a ray over the voxels of occupied bricks: an outer DDA over bricks, an inner one
// over the voxels of each occupied brick; an empty brick is one step and the brick's slot is
// looked up once, not per voxel. Segments come in order and partition the ray inside occupied
// bricks; the field is 0 elsewhere.
struct RsWalk {
  DdaState bricks;
  DdaState voxels;
  bool inBrick;
  uint v;
  uint base;  // index of the current brick's first mean in volCoarse / prevCoarse
  ivec3 origin;
  vec3 o;
  vec3 d;
};

bool rs_walk_start(uint v, vec3 o, vec3 d, float tMax, out RsWalk w) {
  w.inBrick = false;
  w.v = v;
  w.base = 0u;
  w.o = o;
  w.d = d;
  w.origin = v == 0u ? vol.brickOrigin.xyz : prevVol.brickOrigin.xyz;
  if (rsv_empty(v)) return false;
  ivec3 dims = v == 0u ? vol.brickDims.xyz : prevVol.brickDims.xyz;
  return dda_init(w.bricks, o, d, 0.0f, tMax, vec3(w.origin * 8), 8.0f, dims);
}

// The next voxel segment [a, b) in an occupied brick and the voxel's index i in the field buffer
// (its mean and residual bound, two float16: rs_mean_field).
bool rs_walk_next(inout RsWalk w, out float a, out float b, out uint i) {
  a = 0.0f;
  b = 0.0f;
  i = 0u;
  for (;;) {
    if (w.inBrick) {
      ivec3 c;
      if (dda_next(w.voxels, a, b, c)) {
        i = w.base + uint((c.z * 8 + c.y) * 8 + c.x);
        return true;
      }
      w.inBrick = false;
    }
    float ba;
    float bb;
    ivec3 brick;
    if (!dda_next(w.bricks, ba, bb, brick)) return false;
    uint slot = rsv_packed_slot(w.v, w.origin + brick);
    if (slot == 0u) continue;
    ivec3 slots = w.v == 0u ? vol.atlasSlots.xyz : prevVol.atlasSlots.xyz;
    uint index = (slot & 1023u) + uint(slots.x) * (((slot >> 10u) & 1023u) + uint(slots.y) * (slot >> 20u));
    w.base = index * 512u;
    w.inBrick = dda_init(w.voxels, w.o, w.d, ba, bb, vec3((w.origin + brick) * 8), 1.0f, ivec3(8));
  }
  return false;
}

// (mean, residual bound) of voxel i of the current volume's field (bake.h packedMeanField).
vec2 rs_mean_field(uint i) { return unpackHalf2x16(volCoarse[i]); }
float rs_walk_value(RsWalk w, uint i) { return unpackHalf2x16(w.v == 0u ? volCoarse[i] : prevCoarse[i]).x; }

// Optical depth of the coarse trilinear-mean field over (0, tMax) along a world ray
// (deterministic; approximates the fine optical depth, not a bound).
float rs_coarse_tau(uint v, vec3 xWorld, vec3 wWorld, float tMax) {
  vec3 o;
  vec3 d;
  rsv_ray_to_index(v, xWorld, wWorld, o, d);
  RsWalk w;
  if (!rs_walk_start(v, o, d, tMax, w)) return 0.0f;
  float scale = rsv_scale(v);
  float tau = 0.0f;
  float a;
  float b;
  uint i;
  while (tau < RS_MAX_TAU && rs_walk_next(w, a, b, i)) tau += scale * rs_walk_value(w, i) * (b - a);
  return tau;
}

// The cheap deterministic strictly positive transmittance of the target function.
float rs_coarse_tr(uint v, vec3 xWorld, vec3 wWorld, float tMax) {
  return exp(-min(rs_coarse_tau(v, xWorld, wWorld, tMax), RS_MAX_TAU));
}

// Coarse tracking on the current volume's mean field: the first collision in (0, tMax) with pdf
// sigmaC * exp(-tau); false (probability exp(-tau_c(0, tMax))) when the ray leaves first. tau,
// the optical depth to the collision, is also the target's transmittance of the segment, so a
// candidate marches each segment once. (tau <= -log(2^-24) ~ 16.6: the pdf never underflows.)
bool rs_coarse_sample(vec3 xWorld, vec3 wWorld, float tMax, float u, out float t, out float sigmaC, out float tau) {
  t = tMax;
  sigmaC = 0.0f;
  tau = -log(1.0f - u);
  vec3 o;
  vec3 d;
  rsv_ray_to_index(0u, xWorld, wWorld, o, d);
  RsWalk w;
  if (!rs_walk_start(0u, o, d, tMax, w)) return false;
  float scale = rsv_scale(0u);
  float left = tau;
  float a;
  float b;
  uint i;
  while (rs_walk_next(w, a, b, i)) {
    float sigma = scale * rs_mean_field(i).x;
    float dtau = sigma * (b - a);
    if (sigma > 0.0f && dtau >= left) {
      t = a + left / sigma;
      sigmaC = sigma;
      return true;
    }
    left -= dtau;
  }
  return false;
}

#ifndef PLUME_RS_RESIDUAL_SCALE
#define PLUME_RS_RESIDUAL_SCALE 1.0f
#endif

// Unbiased transmittance on the current volume's fine grid by residual ratio tracking (Novák et
// al. 2014) with the coarse mean field as control: T = exp(-tau_mean) * prod_i (1 - (sigma(x_i) -
// sigma_mean(x_i)) / mu), the points x_i a Poisson process of rate mu = PLUME_RS_RESIDUAL_SCALE
// times the cell's residual majorant. Its ratio to the target's exp(-tau_mean) is the product
// alone, with relative variance exp(int r² / mu) - 1 for the residual r: final shading's f / p̂
// stays near 1 where the mean field is close to the fine one, at a cost proportional to the
// residual's optical depth instead of the density's.
float rs_residual_tr(vec3 xWorld, vec3 wWorld, float tMax, inout RngState rng) {
  vec3 o;
  vec3 d;
  rsv_ray_to_index(0u, xWorld, wWorld, o, d);
  RsWalk w;
  if (!rs_walk_start(0u, o, d, tMax, w)) return 1.0f;
  float scale = rsv_scale(0u);
  float tr = 1.0f;  // the estimate so far: exp(-tau_mean) times the residual factors
  float a;
  float b;
  uint i;
  while (tr != 0.0f && rs_walk_next(w, a, b, i)) {
    vec2 field = rs_mean_field(i);
    float mean = scale * field.x;
    tr *= exp(-mean * (b - a));
    float mu = PLUME_RS_RESIDUAL_SCALE * scale * field.y;
    if (!(mu > 0.0f)) continue;
    float t = a;
    for (;;) {
      t -= log(1.0f - rng_float(rng)) / mu;
      if (!(t < b)) break;
      tr *= 1.0f - (scale * rsv_density(0u, o + t * d) - mean) / mu;
    }
  }
  return tr;
}

#endif
