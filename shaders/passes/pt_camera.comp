// The path tracer's camera kernel (pt/wavefront.glsl), a generation's first: every slot's camera
// ray; those that may meet the scene are queued for extension, the others finished with the
// environment they see (pt/integrator.glsl pt_camera).
#version 450
#extension GL_GOOGLE_include_directive : require

#include "../shared/pt_wave.h"

// The host dispatches groups of PT_WAVE_GROUP (render/path_tracer.cpp): one constant for both.
layout(local_size_x = PT_WAVE_GROUP) in;

#include "../volume/bindings.glsl"
#include "../scene/bindings.glsl"
#include "../pt/wavefront.glsl"
#include "../pt/integrator.glsl"

void main() {
  vol_load_params();
  scene_load_params();
  uint i = gl_GlobalInvocationID.x;
  bool live = i < ptPush.slots;
  bool queued = live && pt_camera(i);
  pt_enqueue(PT_TO_EXTEND, i, queued);
}
