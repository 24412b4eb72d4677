// Tier c (DESIGN §7): shared/bsdf.h on the device for tests/test_gpu_bsdf.cpp, which runs the same
// functions compiled as C++ on the same inputs and compares. One thread per case.
#version 450
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;

#include "../shared/bsdf.h"

struct BsdfCase {
  Bsdf bsdf;
  vec4 wo;  // xyz: wo (local frame); w: u.x
  vec4 wi;  // xyz: wi; w: u.y
};
struct BsdfResult {
  vec4 eval;    // xyz: bsdf_eval(wo, wi); w: bsdf_pdf(wo, wi)
  vec4 weight;  // xyz: bsdf_sample's weight; w: its pdf
  vec4 dir;     // xyz: bsdf_sample's wi
};
layout(std430, binding = 0) readonly buffer Cases { BsdfCase cases[]; };
layout(std430, binding = 1) writeonly buffer Results { BsdfResult results[]; };
layout(push_constant) uniform Push { uint count; } pc;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.count) return;
  BsdfCase c = cases[i];
  BsdfResult o;
  o.eval = vec4(bsdf_eval(c.bsdf, c.wo.xyz, c.wi.xyz), bsdf_pdf(c.bsdf, c.wo.xyz, c.wi.xyz));
  vec3 wi;
  float pdf;
  o.weight = vec4(bsdf_sample(c.bsdf, c.wo.xyz, vec2(c.wo.w, c.wi.w), wi, pdf), pdf);
  o.dir = vec4(wi, 0.0f);
  results[i] = o;
}
