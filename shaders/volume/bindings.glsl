// Resources of the baked volume (render/gpu_volume.h binds them in this order).
#ifndef PLUME_VOLUME_BINDINGS_GLSL
#define PLUME_VOLUME_BINDINGS_GLSL

layout(std430, binding = 0) readonly buffer VolumeBuffer { GpuVolume vol; };
layout(binding = 1) uniform sampler3D volAtlas;
layout(std430, binding = 2) readonly buffer IndirectionBuffer { uint volIndirection[]; };
layout(std430, binding = 3) readonly buffer MajorantBuffer { float volMajorants[]; };
// counters[0]: tracking loops truncated by VOL_MAX_STEPS (no silent caps)
layout(std430, binding = 4) buffer CounterBuffer { uint volCounters[]; };

#endif
