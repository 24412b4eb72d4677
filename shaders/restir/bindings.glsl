// Resources of the ReSTIR passes (src/render/restir.cpp binds them in this order). Bindings 0..4
// are the current volume (volume/bindings.glsl); 8..12 its mean field and the previous frame's
// volume (the same resources as the current one for a still grid), which the target function of
// the temporal domain reads (DESIGN §4.2 step 5).
#ifndef PLUME_RESTIR_BINDINGS_GLSL
#define PLUME_RESTIR_BINDINGS_GLSL

#include "../shared/gpu_types.h"
#include "../shared/reservoir.h"
#include "../shared/restir_types.h"
#include "../volume/bindings.glsl"

layout(std430, binding = 5) readonly buffer FrameBuffer { GpuFrame frame; };
layout(std430, binding = 6) readonly buffer LightBuffer { GpuLight lights[]; };
layout(std430, binding = 7) readonly buffer RestirParamBuffer { RestirParams rsp; };
layout(std430, binding = 8) readonly buffer CoarseBuffer { uint volCoarse[]; };  // per voxel: float16 mean, residual (512 per slot)
layout(std430, binding = 9) readonly buffer PrevVolumeBuffer { GpuVolume prevVol; };
layout(binding = 10) uniform sampler3D prevAtlas;
layout(std430, binding = 11) readonly buffer PrevIndirectionBuffer { uint prevIndirection[]; };
layout(std430, binding = 12) readonly buffer PrevCoarseBuffer { uint prevCoarse[]; };
// Reservoir sets: [set * pixels + pixel].
layout(std430, binding = 13) buffer ReservoirBuffer { RsPacked rsReservoirs[]; };
layout(std430, binding = 14) buffer PathBuffer { RsPathHead rsPaths[]; };
// Vertices 2..n of each stored path: [(set * pixels + pixel) * stride + i - 2] = (w_i, t_i).
layout(std430, binding = 15) buffer BounceBuffer { vec4 rsBounces[]; };
// Progressive accumulation of final shading: [2 * pixel] = (mean rgb, n), [2 * pixel + 1] = (M2 rgb, 0).
layout(std430, binding = 16) buffer OutputBuffer { vec4 rsOutput[]; };
// rsCounters[0]: reservoirs whose non-finite weights were dropped on unpack (this frame).
layout(std430, binding = 17) buffer RestirCounterBuffer { uint rsCounters[]; };

layout(push_constant) uniform PushBlock { RsPush push; };

#endif
