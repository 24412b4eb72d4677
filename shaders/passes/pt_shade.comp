// The path tracer's shading kernel (pt/wavefront.glsl): next-event estimation at every collided
// path's new vertex, roulette and phase sampling; the survivors are queued for extension.
#version 450
#extension GL_GOOGLE_include_directive : require

#include "../shared/pt_wave.h"

// The host dispatches groups of PT_WAVE_GROUP (render/path_tracer.cpp): one constant for both.
layout(local_size_x = PT_WAVE_GROUP) in;

#include "../volume/bindings.glsl"
#include "../scene/bindings.glsl"
#include "../pt/wavefront.glsl"
#include "../pt/integrator.glsl"
#include "../volume/loop_guard.glsl"

void main() {
  vol_load_params();
  scene_load_params();
  uint i = gl_GlobalInvocationID.x;
  bool live = i < wave.shadeArgs.w;
  uint slot = live ? ptQueues[ptPush.slots + i] : 0u;
  bool more = live && pt_shade(slot);
  pt_enqueue(PT_TO_EXTEND, slot, more);
  loop_guard_check(frame.loopProbe);
}
