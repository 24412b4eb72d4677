// Resources of the baked volume (render/gpu_volume.cpp binds them; numbers in shared/bindings.h).
// An estimator that needs more of the volume says so before including this file:
//   PLUME_VOL_MEAN_FIELD  the per-voxel mean field (ReSTIR's sampling and target field)
//   PLUME_VOL_PREVIOUS    the previous frame's volume, with its mean field (temporal reuse)
// and a scene whose medium emits defines PLUME_HAS_EMISSION (render/features.cpp).
#ifndef PLUME_VOLUME_BINDINGS_GLSL
#define PLUME_VOLUME_BINDINGS_GLSL

#include "../shared/bindings.h"
#include "../shared/gpu_types.h"

// Every array that lanes read at places of their own is a texel buffer, and the parameter block
// is read once per invocation into a private copy (`vol`, loaded by vol_load_params() at a
// kernel's entry): on a SIMD back end such as lavapipe each storage-buffer read is a scalar loop
// over the lanes with a bounds check per lane, a texel fetch one gather, a private variable a
// register (docs/architecture.md, "Descriptor kinds").
layout(std430, binding = BIND_VOLUME) readonly buffer VolumeBuffer { GpuVolume volParams; };
GpuVolume vol;
layout(binding = BIND_ATLAS) uniform sampler3D volAtlas;
layout(binding = BIND_INDIRECTION) uniform usamplerBuffer volIndirection;  // packed slot per brick
layout(binding = BIND_MAJORANTS) uniform samplerBuffer volMajorants;       // the majorant hierarchy
// volCounters[0]: tracking loops truncated by VOL_MAX_STEPS (no silent caps)
// volCounters[1]: shader invocations whose loops the driver cut (volume/loop_guard.glsl)
layout(std430, binding = BIND_VOLUME_COUNTERS) buffer CounterBuffer { uint volCounters[]; };

#if defined(PLUME_VOL_MEAN_FIELD) || defined(PLUME_VOL_PREVIOUS)
// Per atlas slot 512 words: each voxel's mean and residual bound as two float16.
layout(binding = BIND_MEAN_FIELD) uniform usamplerBuffer volMeanField;
#endif

#ifdef PLUME_HAS_EMISSION
// The emission grid in the density's slots (bake.h emissionF32), and the blackbody table.
layout(binding = BIND_EMISSION_ATLAS) uniform sampler3D volEmissionAtlas;
layout(binding = BIND_BLACKBODY) uniform samplerBuffer volBlackbody;
#endif

#ifdef PLUME_VOL_PREVIOUS
layout(std430, binding = BIND_PREV_VOLUME) readonly buffer PrevVolumeBuffer { GpuVolume prevVolParams; };
GpuVolume prevVol;
layout(binding = BIND_PREV_ATLAS) uniform sampler3D prevAtlas;
layout(binding = BIND_PREV_INDIRECTION) uniform usamplerBuffer prevIndirection;
layout(binding = BIND_PREV_MEAN_FIELD) uniform usamplerBuffer prevMeanField;
#ifdef PLUME_HAS_EMISSION
layout(binding = BIND_PREV_EMISSION_ATLAS) uniform sampler3D prevEmissionAtlas;
#endif
#endif

// The private copies of the parameter blocks: first thing in every kernel that reads the volume.
void vol_load_params() {
  vol = volParams;
#ifdef PLUME_VOL_PREVIOUS
  prevVol = prevVolParams;
#endif
}

#endif
