// CPU mirrors of the shader lookups into a BakedVolume (bake.h), plus the memory report.
// Deliberately free of OpenVDB: this is the arithmetic the GPU performs, texel for texel.
#include "media/bake.h"

#include "core/error.h"

#include <cmath>
#include <cstring>

namespace plume {
namespace {

size_t linearIndex(glm::ivec3 c, glm::ivec3 dims) {
  return (size_t(c.z) * size_t(dims.y) + size_t(c.y)) * size_t(dims.x) + size_t(c.x);
}

bool inside(glm::ivec3 c, glm::ivec3 dims) {
  return c.x >= 0 && c.y >= 0 && c.z >= 0 && c.x < dims.x && c.y < dims.y && c.z < dims.z;
}

// Voxel containing p's lower trilinear corner, and the brick owning it (floor division by 8).
glm::ivec3 baseVoxel(glm::vec3 p) { return glm::ivec3(glm::floor(p)); }
glm::ivec3 brickOfVoxel(glm::ivec3 v) { return v >> 3; }  // arithmetic shift = floor(v / 8)

}  // namespace

float halfToFloat(uint16_t h) {
  const uint32_t sign = uint32_t(h & 0x8000u) << 16;
  const uint32_t exponent = (h >> 10) & 0x1fu, mantissa = h & 0x3ffu;
  uint32_t bits;
  if (exponent == 0) {  // zero or subnormal: mantissa * 2^-24
    const float v = std::ldexp(float(mantissa), -24);
    return sign ? -v : v;
  } else if (exponent == 31) {  // Inf / NaN
    bits = sign | 0x7f800000u | (mantissa << 13);
  } else {  // rebias 15 -> 127
    bits = sign | ((exponent + 112u) << 23) | (mantissa << 13);
  }
  float f;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}

uint32_t brickSlot(const BakedVolume& vol, glm::ivec3 brick) {
  const glm::ivec3 r = brick - vol.brickOrigin;
  return inside(r, vol.brickDims) ? vol.indirection[linearIndex(r, vol.brickDims)] : 0u;
}

glm::ivec3 slotTexelOrigin(const BakedVolume& vol, uint32_t slot) {
  const uint32_t x = uint32_t(vol.atlasSlots.x), y = uint32_t(vol.atlasSlots.y);
  return glm::ivec3(int(slot % x), int((slot / x) % y), int(slot / (x * y))) * kBrickTexels;
}

float atlasTexel(const BakedVolume& vol, glm::ivec3 t) {
  const size_t i = linearIndex(t, vol.atlasTexels);
  return vol.format == TexelFormat::Float32 ? vol.atlasF32[i] : halfToFloat(vol.atlasF16[i]);
}

// d(p) = sum over corners c in {0,1}³ of w_c * v(floor(p) + c), with the exact weights
// w_c = prod_axis (c ? f : 1 - f), f = p - floor(p). Voxel v of brick b sits at texel
// (v - 8b) + 1 of its slot (the apron shifts by one), and v + 1 is still inside the window.
template <typename Texel>
float trilinear(const BakedVolume& vol, glm::vec3 p, Texel&& texel) {
  const glm::vec3 fl = glm::floor(p);
  const glm::ivec3 v = glm::ivec3(fl);
  const glm::ivec3 b = brickOfVoxel(v);
  const uint32_t slot = brickSlot(vol, b);
  if (slot == 0) return 0.0f;
  const glm::vec3 f = p - fl;
  const glm::ivec3 t = slotTexelOrigin(vol, slot) + (v - b * kBrickVoxels) + 1;
  float sum = 0.0f;
  for (int c = 0; c < 8; ++c) {
    const glm::ivec3 o((c & 1), (c >> 1) & 1, (c >> 2) & 1);
    const float w = (o.x ? f.x : 1.0f - f.x) * (o.y ? f.y : 1.0f - f.y) * (o.z ? f.z : 1.0f - f.z);
    sum += w * texel(t + o);
  }
  return sum;
}

float sampleDensity(const BakedVolume& vol, glm::vec3 p) {
  return trilinear(vol, p, [&](glm::ivec3 t) { return atlasTexel(vol, t); });
}

float sampleEmission(const BakedVolume& vol, glm::vec3 p) {
  if (!vol.hasEmission()) return 0.0f;
  return trilinear(vol, p, [&](glm::ivec3 t) { return vol.emissionF32[linearIndex(t, vol.atlasTexels)]; });
}

float sampleMaxLevel(const BakedVolume& vol, int level, glm::vec3 p) {
  if (level < 0 || level >= int(vol.maxLevels.size())) return 0.0f;
  const MaxLevel& L = vol.maxLevels[size_t(level)];
  const glm::ivec3 r = brickOfVoxel(baseVoxel(p)) - vol.brickOrigin;
  if (!inside(r, vol.brickDims)) return 0.0f;  // r >= 0 here, so integer division is floor
  return L.max[linearIndex(r / L.cellBricks, L.dims)];
}

float sampleMajorant(const BakedVolume& vol, glm::vec3 p) { return sampleMaxLevel(vol, 0, p); }

float sampleVoxelMean(const BakedVolume& vol, glm::vec3 p) {
  PLUME_CHECK(!vol.voxelMean.empty());  // baked with BakeOptions::meanField
  const glm::ivec3 v = baseVoxel(p);
  const glm::ivec3 b = brickOfVoxel(v);
  const uint32_t slot = brickSlot(vol, b);
  if (slot == 0) return 0.0f;
  const glm::ivec3 c = v - b * kBrickVoxels;  // 0..7
  return vol.voxelMean[size_t(slot) * 512 + size_t((c.z * kBrickVoxels + c.y) * kBrickVoxels + c.x)];
}

MemoryReport memoryReport(const BakedVolume& vol) {
  MemoryReport m;
  m.atlasBytes = vol.atlasF32.size() * sizeof(float) + vol.atlasF16.size() * sizeof(uint16_t);
  m.indirectionBytes = vol.indirection.size() * sizeof(uint32_t);
  for (const auto& L : vol.maxLevels) m.majorantBytes += L.max.size() * sizeof(float);
  m.coarseBytes = vol.voxelMean.size() * sizeof(uint32_t);  // two float16 per voxel (packedMeanField)
  m.totalBytes = m.atlasBytes + m.indirectionBytes + m.majorantBytes + m.coarseBytes;
  if (vol.stats.activeVoxels) m.bytesPerActiveVoxel = double(m.totalBytes) / double(vol.stats.activeVoxels);
  return m;
}

}  // namespace plume
