// Resources of the baked volume (render/gpu_volume.cpp binds them; numbers in shared/bindings.h).
// An estimator that needs more of the volume says so before including this file:
//   PLUME_VOL_MEAN_FIELD  the per-voxel mean field (ReSTIR's sampling and target field)
//   PLUME_VOL_PREVIOUS    the previous frame's volume, with its mean field (temporal reuse)
// and a scene whose medium emits defines PLUME_HAS_EMISSION (render/features.cpp).
#ifndef PLUME_VOLUME_BINDINGS_GLSL
#define PLUME_VOLUME_BINDINGS_GLSL

#include "../shared/bindings.h"
#include "../shared/gpu_types.h"

layout(std430, binding = BIND_VOLUME) readonly buffer VolumeBuffer { GpuVolume vol; };
layout(binding = BIND_ATLAS) uniform sampler3D volAtlas;
layout(std430, binding = BIND_INDIRECTION) readonly buffer IndirectionBuffer { uint volIndirection[]; };
layout(std430, binding = BIND_MAJORANTS) readonly buffer MajorantBuffer { float volMajorants[]; };
// volCounters[0]: tracking loops truncated by VOL_MAX_STEPS (no silent caps)
// volCounters[1]: shader invocations whose loops the driver cut (volume/loop_guard.glsl)
layout(std430, binding = BIND_VOLUME_COUNTERS) buffer CounterBuffer { uint volCounters[]; };

#if defined(PLUME_VOL_MEAN_FIELD) || defined(PLUME_VOL_PREVIOUS)
// Per atlas slot 512 words: each voxel's mean and residual bound as two float16.
layout(std430, binding = BIND_MEAN_FIELD) readonly buffer MeanFieldBuffer { uint volMeanField[]; };
#endif

#ifdef PLUME_HAS_EMISSION
// The emission grid in the density's slots (bake.h emissionF32), and the blackbody table.
layout(binding = BIND_EMISSION_ATLAS) uniform sampler3D volEmissionAtlas;
layout(std430, binding = BIND_BLACKBODY) readonly buffer BlackbodyBuffer { vec4 volBlackbody[]; };
#endif

#ifdef PLUME_VOL_PREVIOUS
layout(std430, binding = BIND_PREV_VOLUME) readonly buffer PrevVolumeBuffer { GpuVolume prevVol; };
layout(binding = BIND_PREV_ATLAS) uniform sampler3D prevAtlas;
layout(std430, binding = BIND_PREV_INDIRECTION) readonly buffer PrevIndirectionBuffer { uint prevIndirection[]; };
layout(std430, binding = BIND_PREV_MEAN_FIELD) readonly buffer PrevMeanFieldBuffer { uint prevMeanField[]; };
#ifdef PLUME_HAS_EMISSION
layout(binding = BIND_PREV_EMISSION_ATLAS) uniform sampler3D prevEmissionAtlas;
#endif
#endif

#endif
