// The one lookup into a baked volume (DESIGN §3): trilinear density with exact weights
// (8 texelFetch; with PLUME_HW_FILTER, render.density_filter = biased-hardware, one texture()
// through the texture unit's filter instead), per-brick majorants and ReSTIR's per-voxel mean field, for the current volume
// or the previous frame's (temporal reuse), chosen by a parameter `v` (VOL_CURRENT,
// VOL_PREVIOUS), never by a copy of the code. Mirrors media/bake_lookup.cpp texel for texel.
// Requires volume/bindings.glsl.
#ifndef PLUME_VOLUME_GRID_GLSL
#define PLUME_VOLUME_GRID_GLSL

const int VOL_BRICK = 8;     // voxels per brick edge
const int VOL_TEXELS = 10;   // atlas texels per slot edge (the brick and a one-voxel apron)
const uint VOL_BRICK_VOXELS = 512u;  // mean-field words per atlas slot

const uint VOL_CURRENT = 0u;
const uint VOL_PREVIOUS = 1u;

// A field of volume v's parameter block. Without the previous volume bound (the path tracer),
// v is ignored and the current one is read.
#ifdef PLUME_VOL_PREVIOUS
#define VOL_PARAM(v, field) ((v) == VOL_CURRENT ? vol.field : prevVol.field)
#else
#define VOL_PARAM(v, field) (vol.field)
#endif

// Selections between the two volumes' resources are plain ternaries (a select), with no control flow.
#ifdef PLUME_VOL_PREVIOUS
uint vol_indirection(uint v, uint i) {
  return v == VOL_CURRENT ? texelFetch(volIndirection, int(i)).r : texelFetch(prevIndirection, int(i)).r;
}
float vol_texel(uint v, ivec3 t) {
  return v == VOL_CURRENT ? texelFetch(volAtlas, t, 0).r : texelFetch(prevAtlas, t, 0).r;
}
#else
uint vol_indirection(uint v, uint i) { return texelFetch(volIndirection, int(i)).r; }
float vol_texel(uint v, ivec3 t) { return texelFetch(volAtlas, t, 0).r; }
#endif

// The indirection holds each brick's atlas slot as packed slot coordinates (10 bits per axis,
// see GpuVolumeResources); 0 is the all-zero slot. No integer division in the hot loop.
uint vol_packed_slot(uint v, ivec3 brick) {
  ivec3 dims = VOL_PARAM(v, brickDims);
  ivec3 r = brick - VOL_PARAM(v, brickOrigin);
  if (any(lessThan(r, ivec3(0))) || any(greaterThanEqual(r, dims))) return 0u;
  return vol_indirection(v, uint((r.z * dims.y + r.y) * dims.x + r.x));
}

ivec3 vol_slot_coords(uint packed) {
  return ivec3(int(packed & 1023u), int((packed >> 10u) & 1023u), int(packed >> 20u));
}

// Where the trilinear lookup at index-space point p reads volume v's atlas: the texel t of voxel
// floor(p) (its 8 corners are t + {0,1}³) and the weights' fractions f; the voxel's brick slot and
// its place sub in the brick. False where p's brick is empty (every lookup there is 0).
bool vol_locate_voxel(uint v, vec3 p, out uint slot, out ivec3 sub, out ivec3 t, out vec3 f) {
  vec3 fl = floor(p);
  ivec3 vox = ivec3(fl);
  ivec3 b = vox >> 3;
  slot = vol_packed_slot(v, b);
  sub = vox - b * VOL_BRICK;
  f = p - fl;
  t = vol_slot_coords(slot) * VOL_TEXELS + sub + 1;
  return slot != 0u;
}
bool vol_locate(uint v, vec3 p, out ivec3 t, out vec3 f) {
  uint slot;
  ivec3 sub;
  return vol_locate_voxel(v, p, slot, sub, t, f);
}

// Corner c's trilinear weight (exact: the product of the fractions, no hardware filtering).
float vol_corner_weight(int c, vec3 f) {
  return ((c & 1) != 0 ? f.x : 1.0f - f.x) * ((c & 2) != 0 ? f.y : 1.0f - f.y) * ((c & 4) != 0 ? f.z : 1.0f - f.z);
}

#ifdef PLUME_HW_FILTER
// The texture unit's trilinear filter at atlas texel t + f (its sampler is linear: gpu::Image3D).
// The weights are the device's (rounded to VkPhysicalDeviceLimits::subTexelPrecisionBits, 8 on
// most GPUs; lavapipe filters float formats with float weights); still a convex combination of
// the same 8 texels, so the brick majorants bound it. Biased against the exact field by at most
// 3 * 2^-bits of the 8 texels' spread (tests/test_gpu_shared.cpp).
float vol_filter(sampler3D atlas, ivec3 t, vec3 f) {
  return textureLod(atlas, (vec3(t) + f + 0.5f) / vec3(textureSize(atlas, 0)), 0.0f).r;
}
#ifdef PLUME_VOL_PREVIOUS
float vol_filtered(uint v, ivec3 t, vec3 f) {
  return v == VOL_CURRENT ? vol_filter(volAtlas, t, f) : vol_filter(prevAtlas, t, f);
}
#else
float vol_filtered(uint v, ivec3 t, vec3 f) { return vol_filter(volAtlas, t, f); }
#endif
#endif

// The trilinear density of volume v's voxel whose first corner is atlas texel t, at fractions f.
float vol_density_at(uint v, ivec3 t, vec3 f) {
#ifdef PLUME_HW_FILTER
  return vol_filtered(v, t, f);
#else
  float sum = 0.0f;
  for (int c = 0; c < 8; ++c) sum += vol_corner_weight(c, f) * vol_texel(v, t + ivec3(c & 1, (c >> 1) & 1, (c >> 2) & 1));
  return sum;
#endif
}

// Density d at an index-space point (not yet multiplied by the density scale).
float vol_density(uint v, vec3 p) {
  ivec3 t;
  vec3 f;
  if (!vol_locate(v, p, t, f)) return 0.0f;
  return vol_density_at(v, t, f);
}

#ifdef PLUME_HAS_EMISSION
#define BB_TABLE(i) texelFetch(volBlackbody, int(i)).rgb
#include "../shared/blackbody.h"

#ifdef PLUME_VOL_PREVIOUS
float vol_emission_texel(uint v, ivec3 t) {
  return v == VOL_CURRENT ? texelFetch(volEmissionAtlas, t, 0).r : texelFetch(prevEmissionAtlas, t, 0).r;
}
#else
float vol_emission_texel(uint v, ivec3 t) { return texelFetch(volEmissionAtlas, t, 0).r; }
#endif
#ifdef PLUME_HW_FILTER
#ifdef PLUME_VOL_PREVIOUS
float vol_emission_filtered(uint v, ivec3 t, vec3 f) {
  return v == VOL_CURRENT ? vol_filter(volEmissionAtlas, t, f) : vol_filter(prevEmissionAtlas, t, f);
}
#else
float vol_emission_filtered(uint v, ivec3 t, vec3 f) { return vol_filter(volEmissionAtlas, t, f); }
#endif
#endif

// The emitted radiance Le at an index-space point of volume v (DESIGN §2 "Emission"): the
// emission grid e interpolated like the density, then the colour form emissionScale * e or the
// blackbody form emissionScale * B(temperatureScale * (e - temperatureOffset)). The medium emits
// sigma_a * Le per unit length.
vec3 vol_emitted_radiance(uint v, vec3 p) {
  ivec3 t;
  vec3 f;
  if (!vol_locate(v, p, t, f)) return vec3(0.0f);
#ifdef PLUME_HW_FILTER
  float e = vol_emission_filtered(v, t, f);
#else
  float e = 0.0f;
  for (int c = 0; c < 8; ++c) e += vol_corner_weight(c, f) * vol_emission_texel(v, t + ivec3(c & 1, (c >> 1) & 1, (c >> 2) & 1));
#endif
#ifdef PLUME_EMISSION_BLACKBODY
  return VOL_PARAM(v, emissionScale) * bb_lookup(VOL_PARAM(v, temperatureScale) * (e - VOL_PARAM(v, temperatureOffset)));
#else
  return VOL_PARAM(v, emissionScale) * e;
#endif
}
#endif

float vol_scale(uint v) { return VOL_PARAM(v, densityScale); }
bool vol_is_empty(uint v) { return VOL_PARAM(v, empty) != 0; }

// sigma_t at an index-space point.
float vol_sigma_t(uint v, vec3 indexPos) { return vol_scale(v) * vol_density(v, indexPos); }

// The world ray mapped to index space; t stays in world units.
void vol_ray_to_index(uint v, vec3 oWorld, vec3 dWorld, out vec3 o, out vec3 d) {
  mat4 m = VOL_PARAM(v, worldToIndex);
  o = (m * vec4(oWorld, 1.0f)).xyz;
  d = (m * vec4(dWorld, 0.0f)).xyz;
}

// sigma_t at a world point (0 for an empty volume).
float vol_sigma_t_world(uint v, vec3 xWorld) {
  if (vol_is_empty(v)) return 0.0f;
  vec3 o;
  vec3 d;
  vol_ray_to_index(v, xWorld, vec3(0.0f), o, d);
  return vol_sigma_t(v, o);
}

#ifdef PLUME_HAS_EMISSION
// Le at a world point of volume v.
vec3 vol_emitted_radiance_world(uint v, vec3 xWorld) {
  vec3 o;
  vec3 d;
  vol_ray_to_index(v, xWorld, vec3(0.0f), o, d);
  return vol_emitted_radiance(v, o);
}
#endif

// Majorant of sigma_t in a cell of level `level` of the current volume's hierarchy (level 0:
// per brick; cells relative to brickOrigin). Only the current volume is tracked against majorants.
float vol_level_max(int level, ivec3 cell) {
  ivec3 dims = vol.levels[level].cells;
  return texelFetch(volMajorants, int(vol.levelOffset[level]) + (cell.z * dims.y + cell.y) * dims.x + cell.x).r;
}
float vol_brick_majorant(ivec3 cell) { return vol.densityScale * vol_level_max(0, cell); }

#if defined(PLUME_VOL_MEAN_FIELD) || defined(PLUME_VOL_PREVIOUS)
// First mean-field word of the brick in packed slot `slot` (slot index x + X * (y + Y * z)).
uint vol_mean_field_base(uint v, uint slot) {
  ivec3 slots = VOL_PARAM(v, atlasSlots);
  ivec3 s = vol_slot_coords(slot);
  return (uint(s.x) + uint(slots.x) * (uint(s.y) + uint(slots.y) * uint(s.z))) * VOL_BRICK_VOXELS;
}

// Mean-field voxel sub of the brick in packed slot `slot` (its index for vol_mean_field).
uint vol_mean_field_index(uint v, uint slot, ivec3 sub) {
  return vol_mean_field_base(v, slot) + uint((sub.z * VOL_BRICK + sub.y) * VOL_BRICK + sub.x);
}

// (mean, residual bound) of the density in mean-field voxel i (bake.h packedMeanField): the mean
// of the trilinear density over the voxel and a bound on the density's deviation from it.
vec2 vol_mean_field(uint v, uint i) {
#ifdef PLUME_VOL_PREVIOUS
  return unpackHalf2x16(v == VOL_CURRENT ? texelFetch(volMeanField, int(i)).r : texelFetch(prevMeanField, int(i)).r);
#else
  return unpackHalf2x16(texelFetch(volMeanField, int(i)).r);
#endif
}
#endif

#endif
