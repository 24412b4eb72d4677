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
const int RS_COARSE_PER_BRICK = 8;   // cells per brick edge
const float RS_COARSE_CELL = 1.0f;   // voxels per cell edge
const uint RS_COARSE_MEAN = 0u;      // which field: the trilinear mean
const uint RS_COARSE_RESIDUAL = 1u;  // bound on |fine - mean| in the cell (residual tracking)
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

// Value of a cell of the coarse DDA grid (cell 0 = first voxel of brick brickOrigin) in one of
// the two fields (RS_COARSE_MEAN or RS_COARSE_RESIDUAL).
float rsv_coarse_cell(uint v, ivec3 cell, uint field) {
  ivec3 origin = v == 0u ? vol.brickOrigin.xyz : prevVol.brickOrigin.xyz;
  uint slot = rsv_packed_slot(v, origin + cell / RS_COARSE_PER_BRICK);
  if (slot == 0u) return 0.0f;
  ivec3 slots = v == 0u ? vol.atlasSlots.xyz : prevVol.atlasSlots.xyz;
  uint index = (slot & 1023u) + uint(slots.x) * (((slot >> 10u) & 1023u) + uint(slots.y) * (slot >> 20u));
  ivec3 c = cell % RS_COARSE_PER_BRICK;
  uint i = index * 1024u + field * 512u + uint((c.z * RS_COARSE_PER_BRICK + c.y) * RS_COARSE_PER_BRICK + c.x);
  return v == 0u ? volCoarse[i] : prevCoarse[i];
}

bool rsv_coarse_start(uint v, vec3 o, vec3 d, float tMax, out DdaState s) {
  if (rsv_empty(v)) return false;
  ivec3 origin = v == 0u ? vol.brickOrigin.xyz : prevVol.brickOrigin.xyz;
  ivec3 dims = v == 0u ? vol.brickDims.xyz : prevVol.brickDims.xyz;
  return dda_init(s, o, d, 0.0f, tMax, vec3(origin * 8), RS_COARSE_CELL, dims * RS_COARSE_PER_BRICK);
}

// Optical depth of the coarse trilinear-mean field over (0, tMax) along a world ray
// (deterministic; approximates the fine optical depth, not a bound).
float rs_coarse_tau(uint v, vec3 xWorld, vec3 wWorld, float tMax) {
  vec3 o;
  vec3 d;
  rsv_ray_to_index(v, xWorld, wWorld, o, d);
  DdaState s;
  if (!rsv_coarse_start(v, o, d, tMax, s)) return 0.0f;
  float scale = rsv_scale(v);
  float tau = 0.0f;
  float a;
  float b;
  ivec3 cell;
  while (tau < RS_MAX_TAU && dda_next(s, a, b, cell)) tau += scale * rsv_coarse_cell(v, cell, RS_COARSE_MEAN) * (b - a);
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
  DdaState s;
  if (!rsv_coarse_start(0u, o, d, tMax, s)) return false;
  float scale = rsv_scale(0u);
  float left = tau;
  float a;
  float b;
  ivec3 cell;
  while (dda_next(s, a, b, cell)) {
    float sigma = scale * rsv_coarse_cell(0u, cell, RS_COARSE_MEAN);
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
  DdaState s;
  if (!rsv_coarse_start(0u, o, d, tMax, s)) return 1.0f;
  float scale = rsv_scale(0u);
  float tau = 0.0f;
  float prod = 1.0f;
  float a;
  float b;
  ivec3 cell;
  while (prod != 0.0f && dda_next(s, a, b, cell)) {
    float mean = scale * rsv_coarse_cell(0u, cell, RS_COARSE_MEAN);
    tau += mean * (b - a);
    float mu = PLUME_RS_RESIDUAL_SCALE * scale * rsv_coarse_cell(0u, cell, RS_COARSE_RESIDUAL);
    if (!(mu > 0.0f)) continue;
    float t = a;
    for (;;) {
      t -= log(1.0f - rng_float(rng)) / mu;
      if (!(t < b)) break;
      prod *= 1.0f - (scale * rsv_density(0u, o + t * d) - mean) / mu;
    }
  }
  return exp(-tau) * prod;
}

#endif
