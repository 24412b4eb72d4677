// The path tracer's extension kernel (pt/wavefront.glsl): every queued path (the camera rays
// pt_camera.comp queued, or the rays pt_shade.comp drew) to its next real collision; the
// collided ones are queued for shading.
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
  bool live = i < wave.extendArgs.w;
  uint slot = live ? ptQueues[i] : 0u;
  bool collided = live && pt_extend(slot, ptPush.cameraRays != 0u);
  pt_enqueue(PT_TO_SHADE, slot, collided);
  loop_guard_check(frame.loopProbe);
}
