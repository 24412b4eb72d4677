// The path tracer's pass (DESIGN §4.1): one thread per pixel; the integrator is pt/integrator.glsl.
#version 450
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 8, local_size_y = 8) in;

#include "../volume/bindings.glsl"
#include "../scene/bindings.glsl"
// Per pixel: ptAccum[2i] = (mean rgb, n), ptAccum[2i+1] = (M2 rgb, 0).
layout(std430, binding = BIND_PT_ACCUM) buffer AccumBuffer { vec4 ptAccum[]; };

// This dispatch's sample, counted from frame.firstSample (PathTracer::addSamples: one sample per
// dispatch, volume/loop_guard.glsl).
layout(push_constant) uniform PtPush { uint sampleOffset; } ptPush;
#define PT_SAMPLE_OFFSET ptPush.sampleOffset

#include "../pt/integrator.glsl"
#include "../volume/loop_guard.glsl"

void main() {
  uvec2 pixel = gl_GlobalInvocationID.xy;
  if (pixel.x >= frame.size.x || pixel.y >= frame.size.y) return;
  pt_render_pixel(pixel);
  loop_guard_check(frame.loopProbe);
}
