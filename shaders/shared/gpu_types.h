// Structs that cross the bus, shared by C++ and GLSL, grouped by stage: the volume, the scene
// (camera, lights, light choice), the frame. Named fields with explicit padding; a vec3 is always
// followed by a 4-byte scalar, so std430 (storage buffers) and C++ (GLM) agree without hidden
// padding. C++ static_asserts the sizes and offsets (PNanoVDB-style explicit layout contract).
#ifndef PLUME_SHARED_GPU_TYPES_H
#define PLUME_SHARED_GPU_TYPES_H

#include "common.h"

PLUME_NS_BEGIN

const int GPU_MAX_LEVELS = 4;   // max hierarchy levels uploaded (level 0 = per brick)
const int GPU_MAX_LIGHTS = 8;

// --- The baked volume (media/bake.h) as the shaders see it ---------------------------------------
// Index space: voxel centres at integer coordinates; t along rays in world units.
struct GpuVolumeLevel {
  ivec3 cells;           // cells per axis (level 0: the brick grid)
  int bricksPerCell;     // bricks per cell edge (level 0: 1)
};

struct GpuVolume {
  mat4 worldToIndex;
  mat4 indexToWorld;
  ivec3 brickOrigin;     // brick coordinate of indirection cell 0
  int empty;             // 1: no active brick (every lookup reads 0)
  ivec3 brickDims;       // indirection cells per axis
  int texelFormat;       // media/bake.h TexelFormat (informative)
  ivec3 atlasSlots;      // slots per atlas axis
  uint levelCount;       // levels of the majorant hierarchy
  vec3 boundsMin;        // index-space box where d may be > 0
  float densityScale;    // sigma_t = densityScale * d
  vec3 boundsMax;
  uint emission;         // EMISSION_*: the emission channel's form (scene/scene.h Emission)
  GpuVolumeLevel levels[GPU_MAX_LEVELS];
  uvec4 levelOffset;     // [k]: offset of level k in the majorant buffer (floats)
  vec3 emissionScale;    // colour form: scale * color; blackbody form: scale (every channel)
  float temperatureScale;   // blackbody form: T = temperatureScale * (e - temperatureOffset) K
  float temperatureOffset;
  float pad1;
  float pad2;
  float pad3;
};

const uint EMISSION_NONE = 0u;
const uint EMISSION_COLOR = 1u;      // Le = emissionScale * e
const uint EMISSION_BLACKBODY = 2u;  // Le = emissionScale * B(temperatureScale * (e - temperatureOffset))

// --- The scene -----------------------------------------------------------------------------------
const uint LIGHT_SUN = 0u;
const uint LIGHT_POINT = 1u;
const uint LIGHT_ENVIRONMENT = 2u;
const uint LIGHT_ENV_MAP = 3u;  // an environment with a map (shared/envmap.h), at most one

// A light (scene/scene.h Light), ready for sampling (shaders/light/light.glsl).
struct GpuLight {
  vec3 dirOrPos;    // sun: unit direction towards the sun; point: position; environments: unused
  uint type;        // LIGHT_*
  vec3 emission;    // sun: irradiance (delta) or radiance (disk); point: intensity; environment: radiance;
                    // env map: unused (the texels hold radiance times scale)
  float versine;    // sun: the disk's 1 - cos(angular radius), 0 for a delta direction
};

// The environment map's header (shared/envmap.h): the world-to-local rotation's rows
// (R = R_y(-rotate_y_deg) M, DESIGN §2) and the size; the texels and CDFs follow it as float[].
struct GpuEnvMap {
  vec4 toLocal0;  // xyz: row 0 of R (w unused)
  vec4 toLocal1;
  vec4 toLocal2;
  uint width;
  uint height;
  uint pad0;
  uint pad1;
};

// How an estimator that picks one light per sample chooses it (ReSTIR's candidates): its
// probability and the running sum (the last light's is 2, catching rounding).
struct GpuLightChoice {
  float probability;
  float cdf;
};

// A pinhole camera (DESIGN §2): right = normalize(cross(forward, up)), row 0 at the top.
struct GpuCamera {
  vec3 position;
  float tanHalfFovY;
  vec3 forward;
  float aspect;          // width / height
  vec3 right;
  float pad0;
  vec3 up;
  float pad1;
};

// --- Per frame (or per progressive batch) --------------------------------------------------------
struct GpuFrame {
  GpuCamera camera;
  vec3 albedo;           // the medium's single-scattering albedo
  float g;               // its Henyey-Greenstein asymmetry
  uvec2 size;            // image width, height
  uint maxBounces;
  uint seed;             // render seed (random streams)
  uint frameKey;         // frame (and iteration) key of the random streams
  uint firstSample;      // index of this dispatch's first sample (path tracer)
  uint rrStartBounce;    // first bounce at which Russian roulette may end a path
  uint lightCount;
  uint loopProbe;        // 2: the trip count of the driver-loop-limit probe (volume/loop_guard.glsl)
  uint pad1;
  uint pad2;
  uint pad3;
};

// The pinhole camera's (un-normalised) direction through image position p, in pixels from the
// image's top-left corner (row 0 at the top, DESIGN §2).
PLUME_FN vec3 cam_direction(vec2 p, uvec2 size, GpuCamera cam) {
  float sx = (2.0f * p.x / float(size.x) - 1.0f) * cam.tanHalfFovY * cam.aspect;
  float sy = (1.0f - 2.0f * p.y / float(size.y)) * cam.tanHalfFovY;
  return cam.forward + sx * cam.right + sy * cam.up;
}

PLUME_NS_END

#ifdef __cplusplus
#include <cstddef>
static_assert(sizeof(plume::shared::GpuVolumeLevel) == 16, "GpuVolumeLevel layout");
static_assert(offsetof(plume::shared::GpuVolume, brickOrigin) == 128, "GpuVolume layout");
static_assert(offsetof(plume::shared::GpuVolume, densityScale) == 128 + 60, "GpuVolume layout");
static_assert(offsetof(plume::shared::GpuVolume, levels) == 128 + 80, "GpuVolume layout");
static_assert(offsetof(plume::shared::GpuVolume, emissionScale) == 2 * 64 + 5 * 16 + 4 * 16 + 16, "GpuVolume layout");
static_assert(sizeof(plume::shared::GpuVolume) == 2 * 64 + 5 * 16 + 4 * 16 + 16 + 32, "GpuVolume layout");
static_assert(sizeof(plume::shared::GpuLight) == 32, "GpuLight layout");
static_assert(offsetof(plume::shared::GpuLight, emission) == 16, "GpuLight layout");
static_assert(sizeof(plume::shared::GpuLightChoice) == 8, "GpuLightChoice layout");
static_assert(sizeof(plume::shared::GpuEnvMap) == 64, "GpuEnvMap layout");
static_assert(offsetof(plume::shared::GpuEnvMap, width) == 48, "GpuEnvMap layout");
static_assert(sizeof(plume::shared::GpuCamera) == 64, "GpuCamera layout");
static_assert(offsetof(plume::shared::GpuFrame, albedo) == 64, "GpuFrame layout");
static_assert(offsetof(plume::shared::GpuFrame, size) == 80, "GpuFrame layout");
static_assert(offsetof(plume::shared::GpuFrame, maxBounces) == 88, "GpuFrame layout");
static_assert(offsetof(plume::shared::GpuFrame, seed) == 92, "GpuFrame layout");
static_assert(sizeof(plume::shared::GpuFrame) == 8 * 16, "GpuFrame layout");
#endif

#endif
