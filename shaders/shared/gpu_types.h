// Structs that cross the bus, shared by C++ and GLSL. Only vec4/ivec4/uvec4/mat4 members, so
// std430 (storage buffers) and C++ agree without hidden padding; C++ static_asserts the sizes
// and offsets (PNanoVDB-style explicit layout contract).
#ifndef PLUME_SHARED_GPU_TYPES_H
#define PLUME_SHARED_GPU_TYPES_H

#include "common.h"

PLUME_NS_BEGIN

const int GPU_MAX_LEVELS = 4;   // max hierarchy levels uploaded (level 0 = per brick)
const int GPU_MAX_LIGHTS = 8;

const uint LIGHT_SUN = 0u;
const uint LIGHT_POINT = 1u;
const uint LIGHT_ENVIRONMENT = 2u;

// The baked volume (media/bake.h) as the shaders see it. Index space: voxel centres at integer
// coordinates; t along rays in world units.
struct GpuVolume {
  mat4 worldToIndex;
  mat4 indexToWorld;
  ivec4 brickOrigin;     // xyz: brick coordinate of indirection cell 0
  ivec4 brickDims;       // xyz: indirection dims; w: 1 if the volume is empty
  ivec4 atlasSlots;      // xyz: slots per atlas axis
  vec4 boundsMin;        // xyz: index-space box where d may be > 0; w: density scale
  vec4 boundsMax;        // xyz; w: unused
  ivec4 levelDims[GPU_MAX_LEVELS];  // xyz: cells per axis; w: bricks per cell edge
  uvec4 levelOffset;     // offset of level k in the majorant buffer (floats)
  uvec4 info;            // x: number of levels
};

// A light (scene/scene.h Light), ready for sampling.
struct GpuLight {
  vec4 dirOrPos;   // sun: unit direction towards the sun; point: position
  vec4 emission;   // sun: irradiance (delta) or radiance (disk); point: intensity; env: radiance
  vec4 params;     // x: type; y: sun's disk as 1 - cos(angular radius) (0 = delta);
                   // z, w: ReSTIR's light choice probability and running sum (render/restir.cpp)
};

// Per frame (or per progressive batch) parameters.
struct GpuFrame {
  vec4 camPosition;  // w: tan(fovY / 2)
  vec4 camForward;   // w: aspect (width / height)
  vec4 camRight;
  vec4 camUp;
  vec4 albedo;       // xyz; w: HG g
  uvec4 image;       // x: width, y: height, z: spp this batch, w: max bounces
  uvec4 seeds;       // x: seed, y: frame, z: first sample index of this batch, w: RR start bounce
  uvec4 lights;      // x: light count
};

// The pinhole camera's (un-normalised) direction through image position p, in pixels from the
// image's top-left corner (row 0 at the top, DESIGN §2), for a camera in GpuFrame's layout.
PLUME_FN vec3 cam_direction(vec2 p, uvec2 image, vec4 pos, vec4 fwd, vec4 right, vec4 up) {
  float sx = (2.0f * p.x / float(image.x) - 1.0f) * pos.w * fwd.w;
  float sy = (1.0f - 2.0f * p.y / float(image.y)) * pos.w;
  return vec3(fwd) + sx * vec3(right) + sy * vec3(up);
}

PLUME_NS_END

#ifdef __cplusplus
#include <cstddef>
static_assert(sizeof(plume::shared::GpuVolume) == 2 * 64 + 5 * 16 + 4 * 16 + 2 * 16, "GpuVolume layout");
static_assert(offsetof(plume::shared::GpuVolume, levelDims) == 128 + 80, "GpuVolume layout");
static_assert(sizeof(plume::shared::GpuLight) == 48, "GpuLight layout");
static_assert(sizeof(plume::shared::GpuFrame) == 8 * 16, "GpuFrame layout");
static_assert(offsetof(plume::shared::GpuFrame, image) == 80, "GpuFrame layout");
#endif

#endif
