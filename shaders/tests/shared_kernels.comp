// Tier c (DESIGN §7): runs the shared headers on the GPU for tests/test_gpu_shared.cpp, which
// runs the same functions compiled as C++ and compares. One thread per test case.
#version 450
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;

#include "../shared/gpu_types.h"
#include "../volume/bindings.glsl"
#include "../shared/rng.h"
#include "../volume/grid.glsl"
#include "../shared/phase.h"
#include "../shared/sampling.h"

struct KernelCase {
  vec4 point;   // xyz: index-space point for vol_density; w: g
  vec4 dir;     // xyz: unit direction wi; w: cosTheta for ph_hg
  uvec4 seed;   // pixel.x, pixel.y, frame, seed
};
struct KernelResult {
  uvec4 rng0;   // first 8 rng_uint draws
  uvec4 rng1;
  vec4 phase;   // x: ph_hg(cos, g), y: ph_hg_sample_cos(g, u), z: vol_density(point)
  vec4 hgDir;   // ph_hg_sample(wi, g, u2)
  vec4 coneDir; // smp_uniform_cone(wi, 0.1, u2)
  uvec4 walk;   // after those: a walk generator's first four rng_walk_next
};

// Bindings after the volume's (shared/bindings.h): this test pass's own.
const uint BIND_TEST_CASES = BIND_VOLUME_COUNTERS + 1u;
const uint BIND_TEST_RESULTS = BIND_VOLUME_COUNTERS + 2u;
layout(std430, binding = BIND_TEST_CASES) readonly buffer Cases { KernelCase cases[]; };
layout(std430, binding = BIND_TEST_RESULTS) writeonly buffer Results { KernelResult results[]; };
layout(push_constant) uniform Push { uint count; } pc;

void main() {
  vol_load_params();
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.count) return;
  KernelCase c = cases[i];
  RngState r = rng_init(c.seed.xy, c.seed.z, RNG_STREAM_TEST, c.seed.w);
  KernelResult o;
  o.rng0 = uvec4(rng_uint(r), rng_uint(r), rng_uint(r), rng_uint(r));
  o.rng1 = uvec4(rng_uint(r), rng_uint(r), rng_uint(r), rng_uint(r));
  float g = c.point.w;
  vec2 u = rng_float2(r);
  o.phase = vec4(ph_hg(c.dir.w, g), ph_hg_sample_cos(g, u.x), vol_density(VOL_CURRENT, c.point.xyz), 0.0f);
  o.hgDir = vec4(ph_hg_sample(c.dir.xyz, g, u), 0.0f);
  o.coneDir = vec4(smp_uniform_cone(c.dir.xyz, 0.1f, u), 0.0f);
  RngWalk walk = rng_walk_init(r);
  o.walk.x = rng_walk_next(walk);
  o.walk.y = rng_walk_next(walk);
  o.walk.z = rng_walk_next(walk);
  o.walk.w = rng_walk_next(walk);
  results[i] = o;
}
