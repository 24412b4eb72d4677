// The wavefront path tracer's shared layouts (shaders/pt/wavefront.glsl, render/path_tracer.cpp):
// a generation of path slots, its two queues and the indirect dispatches of its kernels.
// A slot is one sample of one pixel: slot i of a generation holds sample
// sampleBase + i / pixelCount of the pixel at entry pixelBegin + i % pixelCount of the pixel list
// (neighbouring lanes trace neighbouring pixels). The list (render/pixel_order.h) holds first the
// pixels whose camera rays may meet the scene, which the generations trace, then those whose every
// ray misses it, which pt_background.comp finishes with the environment they see.
#ifndef PLUME_SHARED_PT_WAVE_H
#define PLUME_SHARED_PT_WAVE_H

#include "common.h"

PLUME_NS_BEGIN

const uint PT_WAVE_GROUP = 64u;  // invocations per workgroup of the queue kernels
const uint PT_PATH_TEXELS = 5u;  // a slot's path between kernels: texels of 4 words (PtPath, pt/wavefront.glsl)

// Queue lengths and the indirect dispatches (x, y, z groups; w the queue's length) of the two
// queue kernels. extendCount is appended to by shading, shadeCount by extension; pt_queue.comp
// turns one into the other kernel's dispatch and empties the queue just consumed.
struct PtWave {
  uint extendCount;
  uint shadeCount;
  uint pad0;
  uint pad1;
  uvec4 extendArgs;
  uvec4 shadeArgs;
};

// Push constants of every wavefront kernel (one layout for all).
struct PtPush {
  uint cameraRays;   // pt_extend: 1 = the generation's first extension (the queued camera rays)
  uint pixelBegin;   // the generation's first entry of the pixel list (BIND_PT_PIXELS)
  uint pixelCount;   // its pixels (pt_background: the pixels it merges)
  uint sampleBase;   // the sample of its slot 0, counted from frame.firstSample (pt_background: its first)
  uint slots;        // pixelCount times its samples per pixel (pt_background: the samples it merges)
  uint stage;        // pt_queue: PT_QUEUE_TO_SHADE or PT_QUEUE_TO_EXTEND
  uint accumBase;    // pt_resolve, pt_background: the pixel index of the bound accumulation's first
  uint listed;       // 1: the pixel list holds the order; 0: row-major, entry i is pixel i (no list)
};

const uint PT_QUEUE_TO_SHADE = 0u;   // after extension: dispatch shading, empty the extend queue
const uint PT_QUEUE_TO_EXTEND = 1u;  // after shading: dispatch extension, empty the shade queue

PLUME_NS_END

#ifdef __cplusplus
#include <cstddef>
static_assert(sizeof(plume::shared::PtWave) == 48, "PtWave layout");
static_assert(offsetof(plume::shared::PtWave, extendArgs) == 16, "PtWave layout");
static_assert(offsetof(plume::shared::PtWave, shadeArgs) == 32, "PtWave layout");
static_assert(sizeof(plume::shared::PtPush) == 32, "PtPush layout");
#endif

#endif
