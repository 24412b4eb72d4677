// The wavefront path tracer's state (DESIGN §4.1; render/path_tracer.cpp drives it): a generation
// of path slots (shared/pt_wave.h), each slot's path between its kernels, and the two queues.
// pt_camera.comp makes every slot's camera ray and queues those that may meet the scene;
// pt_extend.comp takes every queued path to its next real collision or out of the volume;
// pt_shade.comp estimates next-event transmittance at the collided ones, then rolls the roulette
// and samples the phase function; pt_queue.comp turns one kernel's output queue into the other's
// indirect dispatch; pt_resolve.comp merges a generation's samples into the accumulation. Every
// kernel's hot loop holds only its own code, runs on densely packed lanes, and no invocation
// walks more than one path segment and its shadow rays (llvmpipe's loop budget,
// volume/loop_guard.glsl).
// Requires scene/bindings.glsl.
#ifndef PLUME_PT_WAVEFRONT_GLSL
#define PLUME_PT_WAVEFRONT_GLSL

#ifndef PLUME_NO_SUBGROUP_BALLOT
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
#endif

#include "../shared/pt_wave.h"
#include "../shared/rng.h"

// A path between kernels: after pt_extend, origin is its newest vertex; after pt_shade, origin
// and dir are the ray leaving it. counter: the draw counter of the slot's random stream (the key is a
// hash of pixel and sample, recomputed by every kernel).
struct PtPath {
  vec3 origin;
  float phasePdf;  // the pdf with which the last vertex drew dir (an environment map's MIS)
  vec3 dir;
  uint scatterings;
  vec3 beta;
  uint counter;
  vec3 radiance;
  uint prim;     // the vertex's triangle (input index), PT_MEDIUM_VERTEX for a medium collision
  vec3 shading;  // a surface vertex's shading normal
  uint pad;
};

const uint PT_MEDIUM_VERTEX = 0xffffffffu;

// The path slots, PT_PATH_TEXELS texels of four words each in PtPath's std430 layout (origin and
// phasePdf, dir and scatterings, beta and counter, radiance and prim, shading), bound twice: as a
// storage buffer of PtPath, written field by field (only the fields a kernel changes), and as a
// uniform texel buffer of uvec4, read a texel at a time. On a SIMD back end such as lavapipe a
// storage buffer's per-lane word is a scalar loop over the lanes with a bounds check each, a
// texel fetch one gather (docs/architecture.md, "Descriptor kinds"); a texel store through a
// storage texel buffer was slower still than the word stores (session 28, the bundled smoke at
// 128², 16 samples: the camera kernel 5.0 -> 6.7 ms, extension 13.1 -> 15.2). The texel reads made
// extension and shading ~2-3% faster than the word reads.
layout(std430, binding = BIND_PT_PATHS) buffer PathBuffer { PtPath ptPaths[]; };
layout(binding = BIND_PT_PATH_TEXELS) uniform usamplerBuffer ptPathTexels;
uvec4 pt_texel(uint slot, uint k) { return texelFetch(ptPathTexels, int(slot * PT_PATH_TEXELS + k)); }
vec3 pt_xyz(uvec4 t) { return uintBitsToFloat(t.xyz); }

// The path's radiance so far (the resolve's read: a storage buffer's, faster there than the texel
// fetch, whose lanes each read another slot's cache line).
vec3 pt_radiance(uint slot) { return ptPaths[slot].radiance; }
void pt_set_radiance(uint slot, vec3 radiance) { ptPaths[slot].radiance = radiance; }

// [0, slots): the paths to extend; [slots, 2 slots): the paths to shade.
layout(std430, binding = BIND_PT_QUEUES) buffer QueueBuffer { uint ptQueues[]; };
layout(std430, binding = BIND_PT_WAVE) buffer WaveBuffer { PtWave wave; };
layout(push_constant) uniform PtPushBlock { PtPush ptPush; };

// A path is read a texel at a time and written field by field, only what a kernel needs or
// changes. Extension reads the ray it follows and what it adds to (atVertex false); shading, the
// vertex it waits at (atVertex true; a constant at each call).
PtPath pt_load(uint slot, const bool atVertex) {
  PtPath p;
  uvec4 t0 = pt_texel(slot, 0u);
  uvec4 t1 = pt_texel(slot, 1u);
  uvec4 t2 = pt_texel(slot, 2u);
  uvec4 t3 = pt_texel(slot, 3u);
  p.origin = pt_xyz(t0);
  p.phasePdf = uintBitsToFloat(t0.w);
  p.dir = pt_xyz(t1);
  p.scatterings = t1.w;
  p.beta = pt_xyz(t2);
  p.counter = t2.w;
  p.radiance = pt_xyz(t3);
  p.prim = PT_MEDIUM_VERTEX;
  p.shading = vec3(0.0f);
#ifdef PLUME_HAS_SURFACES
  // Extension reads the triangle of the vertex its ray leaves (emitter hits' MIS), shading that
  // of the vertex it waits at.
  p.prim = t3.w;
  if (atVertex) p.shading = pt_xyz(pt_texel(slot, 4u));
#endif
  p.pad = 0u;
  return p;
}

// After extension: the vertex (or the finished path's radiance).
void pt_store_vertex(uint slot, PtPath p) {
  ptPaths[slot].origin = p.origin;
  ptPaths[slot].scatterings = p.scatterings;
  ptPaths[slot].beta = p.beta;
  ptPaths[slot].counter = p.counter;
  ptPaths[slot].radiance = p.radiance;
#ifdef PLUME_HAS_SURFACES
  ptPaths[slot].prim = p.prim;
  ptPaths[slot].shading = p.shading;
#endif
}

// After shading, for a path that goes on: the ray leaving its vertex.
void pt_store_ray(uint slot, PtPath p) {
  ptPaths[slot].counter = p.counter;
  ptPaths[slot].origin = p.origin;
  ptPaths[slot].phasePdf = p.phasePdf;
  ptPaths[slot].dir = p.dir;
  ptPaths[slot].beta = p.beta;
}

// The frame's pixels in the kernels' order (shared/pt_wave.h), packed x | y << 16; without a
// list (ptPush.listed 0: an image whose accumulation is split, in row order) entry i is pixel i.
layout(binding = BIND_PT_PIXELS) uniform usamplerBuffer ptPixels;
uvec2 pt_list_pixel(uint entry) {
  if (ptPush.listed == 0u) return uvec2(entry % frame.size.x, entry / frame.size.x);
  uint packed = texelFetch(ptPixels, int(entry)).r;
  return uvec2(packed & 0xffffu, packed >> 16u);
}

// The pixel of a slot, and the index of its sample in the frame.
uint pt_slot_sample(uint slot, out uvec2 pixel) {
  pixel = pt_list_pixel(ptPush.pixelBegin + slot % ptPush.pixelCount);
  return frame.firstSample + ptPush.sampleBase + slot / ptPush.pixelCount;
}

// The random stream of sample `sampleIndex` of a pixel (DESIGN §2).
RngState pt_sample_rng(uvec2 pixel, uint sampleIndex) {
  return rng_init(pixel, frame.frameKey, RNG_STREAM_PATH + (sampleIndex << 8u), frame.seed);
}

// The slot's random stream at draw `counter` (the stream of sample s of a pixel: DESIGN §2).
RngState pt_slot_rng(uint slot, uint counter) {
  uvec2 pixel;
  uint sampleIndex = pt_slot_sample(slot, pixel);
  RngState rng = pt_sample_rng(pixel, sampleIndex);
  rng.counter = counter;
  return rng;
}

const uint PT_TO_EXTEND = 0u;
const uint PT_TO_SHADE = 1u;

// Appends `slot` to a queue where `push` (every lane of the subgroup calls this together): one
// atomic per subgroup, each lane's place from the ballot (per-lane atomics loop over the lanes on
// a SIMD back end).
void pt_enqueue(const uint queue, uint slot, bool push) {
#ifdef PLUME_NO_SUBGROUP_BALLOT
  if (!push) return;
  uint at = queue == PT_TO_SHADE ? atomicAdd(wave.shadeCount, 1u) : atomicAdd(wave.extendCount, 1u);
#else
  uvec4 ballot = subgroupBallot(push);
  uint n = subgroupBallotBitCount(ballot);
  uint base = 0u;
  if (subgroupElect() && n > 0u) base = queue == PT_TO_SHADE ? atomicAdd(wave.shadeCount, n) : atomicAdd(wave.extendCount, n);
  base = subgroupBroadcastFirst(base);
  if (!push) return;
  uint at = base + subgroupBallotExclusiveBitCount(ballot);
#endif
  ptQueues[(queue == PT_TO_SHADE ? ptPush.slots : 0u) + at] = slot;
}

#endif
