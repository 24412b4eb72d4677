// The wavefront path tracer's shared layouts (shaders/pt/wavefront.glsl, render/path_tracer.cpp):
// a generation of path slots, its two queues and the indirect dispatches of its kernels.
// A slot is one sample of one pixel: slot i of a generation holds sample
// sampleBase + i / pixelCount of pixel pixelBegin + i % pixelCount (neighbouring lanes trace
// neighbouring pixels).
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
  uint pixelBegin;   // the generation's first pixel (row-major)
  uint pixelCount;   // its pixels
  uint sampleBase;   // the sample of its slot 0, counted from frame.firstSample
  uint slots;        // pixelCount times its samples per pixel
  uint stage;        // pt_queue: PT_QUEUE_TO_SHADE or PT_QUEUE_TO_EXTEND
};

const uint PT_QUEUE_TO_SHADE = 0u;   // after extension: dispatch shading, empty the extend queue
const uint PT_QUEUE_TO_EXTEND = 1u;  // after shading: dispatch extension, empty the shade queue

PLUME_NS_END

#ifdef __cplusplus
#include <cstddef>
static_assert(sizeof(plume::shared::PtWave) == 48, "PtWave layout");
static_assert(offsetof(plume::shared::PtWave, extendArgs) == 16, "PtWave layout");
static_assert(offsetof(plume::shared::PtWave, shadeArgs) == 32, "PtWave layout");
static_assert(sizeof(plume::shared::PtPush) == 24, "PtPush layout");
#endif

#endif
