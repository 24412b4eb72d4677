// Binding numbers of every compute pass, named once for C++ and GLSL (in the manner of RTXDI's
// RAB_Buffers): the shaders declare `layout(binding = BIND_...)`, the host binds by the same name.
// Each estimator declares its own buffers and nothing else; numbers may repeat across estimators.
#ifndef PLUME_SHARED_BINDINGS_H
#define PLUME_SHARED_BINDINGS_H

#include "common.h"

PLUME_NS_BEGIN

// The baked volume (shaders/volume/bindings.glsl; render/gpu_volume.cpp), every volume pass.
const uint BIND_VOLUME = 0u;           // GpuVolume
const uint BIND_ATLAS = 1u;            // sampler3D: the brick atlas
const uint BIND_INDIRECTION = 2u;      // uint[]: packed slot coordinates per brick
const uint BIND_MAJORANTS = 3u;        // float[]: the majorant hierarchy
const uint BIND_VOLUME_COUNTERS = 4u;  // uint[]: [0] tracking loops truncated by the step cap

// The scene, every estimator.
const uint BIND_FRAME = 5u;            // GpuFrame
const uint BIND_LIGHTS = 6u;           // GpuLight[]

// The wavefront path tracer (shaders/pt/wavefront.glsl, shaders/passes/pt_*.comp).
const uint BIND_PT_ACCUM = 7u;         // per pixel: vec4(mean rgb, n), vec4(M2 rgb, 0)
const uint BIND_PT_PATHS = 8u;         // per path slot: PT_PATH_TEXELS uvec4 texels (PtPath)
const uint BIND_PT_QUEUES = 9u;        // uint[2 * slots]: the paths to extend, then those to shade
const uint BIND_PT_WAVE = 10u;         // PtWave: queue lengths and the indirect dispatches
const uint BIND_PT_PATH_TEXELS = 15u;  // the path slots again, read as a uniform texel buffer
const uint BIND_PT_PIXELS = 16u;       // uint[]: the pixel list, packed x | y << 16 (render/pixel_order.h)

// The scene's surfaces (shaders/surface/surfaces.glsl; render/gpu_surfaces.cpp), in the
// estimators that render them (PLUME_HAS_SURFACES).
const uint BIND_BVH = 11u;             // the BVH's header, nodes and triangles (shared/bvh.h)
const uint BIND_SURF_TRIANGLES = 12u;  // GpuSurfaceTriangle[], by input index
const uint BIND_SURF_MATERIALS = 13u;  // GpuSurfaceMaterial[], by surface
const uint BIND_EMITTERS = 14u;        // GpuLightNode[]: the emissive triangles' light tree

// ReSTIR (shaders/restir/bindings.glsl): its parameters, the current volume's mean field, the
// previous frame's volume (temporal reuse evaluates the history's target with it), reservoirs.
const uint BIND_RS_PARAMS = 7u;        // RestirParams
const uint BIND_MEAN_FIELD = 8u;       // uint[]: per voxel float16 mean and residual bound
const uint BIND_PREV_VOLUME = 9u;
const uint BIND_PREV_ATLAS = 10u;
const uint BIND_PREV_INDIRECTION = 11u;
const uint BIND_PREV_MEAN_FIELD = 12u;
// The reservoirs, the paths and the passes' state are storage texel buffers (restir/bindings.glsl).
const uint BIND_RS_RESERVOIRS = 13u;   // RsPacked of [set * pixels + pixel], one uvec4 texel each
const uint BIND_RS_PATHS = 14u;        // RsPathHead[set * pixels + pixel] in uvec4 texels, then the state
const uint BIND_RS_BOUNCES = 15u;      // vec4(w_i, t_i) of vertices 2..n
const uint BIND_RS_OUTPUT = 16u;       // accumulation of final shading (as BIND_PT_ACCUM)
const uint BIND_RS_COUNTERS = 17u;     // uint[]: [0] reservoirs dropped for non-finite weights
const uint BIND_LIGHT_CHOICE = 18u;    // GpuLightChoice[]
const uint RS_BINDING_COUNT = 20u;     // up to BIND_ENV_MAP

// The scene's environment map, every estimator (shared/envmap.h: GpuEnvMap, then float data);
// read only by variants compiled with PLUME_HAS_ENV_MAP, a 1-texel black map otherwise.
const uint BIND_ENV_MAP = 19u;

// A medium's emission (shaders/volume/bindings.glsl with PLUME_HAS_EMISSION), every estimator.
const uint BIND_EMISSION_ATLAS = 20u;  // sampler3D: the emission grid in the atlas layout, R32F
const uint BIND_BLACKBODY = 21u;       // vec4[]: the blackbody table (shared/blackbody.h)
const uint BIND_PREV_EMISSION_ATLAS = 22u;  // sampler3D: the previous frame's (ReSTIR's history)
const uint EMISSION_BINDING_COUNT = 23u;  // binding tables that may hold the emission extend to it

// ReSTIR's passes hold the surfaces' buffers (BIND_BVH .. BIND_EMITTERS) shifted by this
// (PLUME_SURF_BINDING_SHIFT in surface/surfaces.glsl): 23 .. 26, past the emission's.
const uint RS_SURF_BINDING_SHIFT = EMISSION_BINDING_COUNT - BIND_BVH;
const uint RS_SURFACE_BINDING_COUNT = BIND_EMITTERS + RS_SURF_BINDING_SHIFT + 1u;

PLUME_NS_END

#endif
