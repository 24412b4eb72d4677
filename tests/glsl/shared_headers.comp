// Compile test (tests/CMakeLists.txt, ctest glsl_shared_headers): every shaders/shared/*.h
// must compile as GLSL 450 for Vulkan 1.1. Each shared function is called once so that glslang
// type-checks its body; the results go to a buffer so nothing is dead code.
// A new header in shaders/shared must be included and exercised here (glsl_shared_headers_listed
// checks that it is included).
#version 450
#extension GL_GOOGLE_include_directive : require

#include "shared/common.h"
#include "shared/accumulate.h"
#include "shared/rng.h"
#include "shared/phase.h"
#include "shared/sampling.h"
#include "shared/reservoir.h"
#include "shared/dda.h"
#include "shared/gpu_types.h"
#include "shared/restir_types.h"
#include "shared/bindings.h"
#include "shared/kernel_counters.h"
#include "shared/bvh.h"
#include "shared/bsdf.h"
#include "shared/pt_wave.h"
#include "shared/surface_types.h"
#include "shared/light_tree.h"

// restir_mis.h reads its inputs through accessor macros (here: small tables).
float misM[3];
float misTargets[9];
#define RS_MIS_M(j) misM[j]
#define RS_MIS_OWN_TARGET(s) misTargets[(s) * 3u + (s)]
#define RS_MIS_TARGET(s, j) misTargets[(s) * 3u + (j)]
#include "shared/restir_mis.h"

layout(local_size_x = 64) in;

layout(std430, binding = 0) buffer Out {
  vec4 values[];
};
layout(std430, binding = 1) buffer Reservoirs {
  RsPacked reservoirs[];
};
layout(std430, binding = 2) readonly buffer Params {
  GpuVolume volume;
  GpuFrame frame;
  GpuLight lights[GPU_MAX_LIGHTS];
  GpuLightChoice choice[GPU_MAX_LIGHTS];
  RestirParams rsParams;
};
// envmap.h reads the global envData[] after its GpuEnvMap header (scene/bindings.glsl).
layout(std430, binding = 3) readonly buffer EnvMapBuffer {
  GpuEnvMap envMap;
  float envData[];
};
#include "shared/envmap.h"
// blackbody.h reads its table through BB_TABLE(i) (grid.glsl: the blackbody buffer).
layout(std430, binding = 4) readonly buffer BlackbodyBuffer {
  vec4 bbTable[];
};
#define BB_TABLE(i) bbTable[i].rgb
#include "shared/blackbody.h"
// bvh.h: the layout only (surface/bvh.glsl traverses it; shaders/tests/bvh_kernels.comp runs it).
layout(std430, binding = 5) readonly buffer BvhBuffer {
  BvhNode bvhNodes[2];
  BvhTriangle bvhTriangles[];
};

void main() {
  uint i = gl_GlobalInvocationID.x;
  // rng.h
  RngState rng = rng_init(gl_GlobalInvocationID.xy, 0u, RNG_STREAM_TEST, 1u);
  uvec4 h = rng_next4(rng);
  float u0 = rng_float(rng) + rng_to_float(rng_uint(rng)) + float(h.x & 1u);
  vec2 u = rng_float2(rng);
  // common.h
  vec3 b1;
  vec3 b2;
  plume_onb(vec3(0.0f, 0.0f, 1.0f), b1, b2);
  float m = plume_max3(b1 + b2) * PLUME_PI * PLUME_INV_PI * PLUME_INV_4PI;
  // phase.h
  vec3 wo = ph_hg_sample(vec3(0.0f, 1.0f, 0.0f), 0.5f, u);
  float sin2Theta;
  float p = ph_hg(wo.y, 0.5f) + ph_hg_sample_cos(-0.3f, u.x) +
            ph_hg_sample_cos_sin2(0.9f, u.y, sin2Theta) + sin2Theta;
  // sampling.h
  float t = smp_exponential(2.0f, u0 * 0.25f);
  vec3 s = smp_uniform_sphere(u) + smp_uniform_cone(wo, 0.1f, u);
  float pc = smp_uniform_cone_pdf(0.1f) + smp_versine(wo, s);
  // reservoir.h
  RsReservoir r = rs_empty();
  bool picked = rs_stream(r, p, pc, 0.5f, u.x);
  picked = rs_update(r, 0.25f, p, 1.0f, u.y) || picked;
  RsReservoir other = r;
  rs_finalize(other);
  picked = rs_merge(r, other, p, 1.0f, 0.5f, u0) || picked;
  rs_cap_confidence(r, 20.0f);
  rs_finalize(r);
  bool dropped;
  RsReservoir back = rs_unpack(rs_pack(r), dropped);
  reservoirs[i] = rs_pack(back);
  // dda.h, gpu_types.h
  DdaState dda;
  float t0 = 0.0f;
  float t1 = 0.0f;
  ivec3 cell = ivec3(0);
  if (dda_init(dda, vec3(0.5f), wo, 0.0f, DDA_INF, volume.boundsMin, 8.0f, volume.brickDims)) {
    dda_next(dda, t0, t1, cell);
  }
  s += vec3(cell) * (t1 - t0) + frame.albedo + lights[0].emission + vec3(choice[0].probability, choice[0].cdf, float(BIND_LIGHT_CHOICE));
  s += cam_direction(vec2(0.5f), frame.size, frame.camera) + rsParams.prevCamera.position;
  // accumulate.h
  vec4 acc = vec4(0.0f);
  vec3 m2 = vec3(0.0f);
  acc_merge(acc, m2, s, vec3(0.0f), 1.0f);
  s += acc.xyz + m2;
  // restir_types.h
  vec3 wd = rs_decode_dir(rs_encode_dir(wo));
  float mis = rs_pairwise_neighbour(1.0f, p, 2.0f, pc, 3.0f) + rs_pairwise_canonical_term(1.0f, p, 2.0f, pc, 3.0f) +
              rs_pair_share(1.0f, p, 1.0f, pc) + rs_gbh(1.0f, p, 2.0f) +
              float(RS_MAX_VERTICES + RS_MAX_NEIGHBOURS + RS_MIS_PAIRWISE + RS_MIS_GBH + RS_MIS_BIASED);
  for (uint k = 0u; k < 9u; ++k) misTargets[k] = p + float(k);
  for (uint k = 0u; k < 3u; ++k) misM[k] = 1.0f + float(k);
  mis += rs_mis_weight(RS_MIS_PAIRWISE, 1u, 3u, 6.0f, pc) + rs_mis_weight(RS_MIS_GBH, 0u, 3u, 6.0f, pc);
  s += wd * mis;
  // envmap.h
  vec3 we = env_sample(envMap, u);
  uvec2 tx = env_texel(envMap, env_local_uv(env_to_local(envMap, we)));
  s += env_radiance(envMap, we) * (env_pdf(envMap, we) + env_texel_probability(envMap, tx) +
                                   env_luminance(env_uv_local(u)) + float(env_data_size(2u, 1u)) +
                                   float(env_find_interval(env_marginal_offset(envMap), envMap.height, u.x)) +
                                   float(env_conditional_offset(envMap, 0u)) + float(BIND_ENV_MAP)) +
       env_to_world(envMap, we);
  // blackbody.h
  s += bb_lookup(1000.0f + 9000.0f * u.x) * bb_table_kelvin(i % BB_TABLE_SIZE) * BB_TABLE_MAX_K * BB_TABLE_MIN_K +
       vec3(float(BIND_BLACKBODY + BIND_EMISSION_ATLAS + BIND_PREV_EMISSION_ATLAS + EMISSION_BINDING_COUNT));
  // kernel_counters.h
  s += vec3(float(KC_WORDS + KC_WALKS + KC_SEGMENTS + KC_SEGMENT_ITERS + KC_STEPS + KC_STEP_ITERS + KC_LOOKUPS +
                  KC_LOOKUP_ITERS));
  // bvh.h
  BvhNode bn = bvhNodes[0];
  BvhTriangle bt = bvhTriangles[bn.ref0 % 2u];
  BvhHit bh;
  bh.t = bn.lo1.x + bn.hi0.y;
  bh.prim = bt.prim + bn.count0 + bn.count1 + bn.ref1 + BVH_NONE + BVH_MAX_LEAF_SIZE + uint(BVH_MAX_DEPTH + BVH_STACK_SIZE);
  bh.u = bt.v1.x;
  bh.v = bt.v2.y;
  s += bn.hi1 + bt.v0 + vec3(bh.t, float(bh.prim), bh.u + bh.v);
  // bsdf.h
  Bsdf bsdf;
  bsdf.color = vec3(0.5f);
  bsdf.type = i % 2u == 0u ? BSDF_DIFFUSE : BSDF_CONDUCTOR;
  bsdf.alpha = 0.3f;
  bsdf.pad0 = bsdf.pad1 = bsdf.pad2 = 0.0f;
  vec3 bwi;
  float bpdf;
  s += bsdf_sample(bsdf, wo, u, bwi, bpdf) * bpdf + bsdf_eval(bsdf, wo, bwi) * bsdf_pdf(bsdf, wo, bwi) +
       bsdf_schlick(vec3(0.04f), u.x) * (bsdf_ggx_d(wo, 0.2f) + bsdf_ggx_g1(wo, 0.2f) + bsdf_ggx_g2(wo, bwi, 0.2f)) +
       bsdf_ggx_eval(vec3(1.0f), 0.1f, wo, bwi) * (bsdf_ggx_pdf(0.1f, wo, bwi) + bsdf_lambert_pdf(wo, bwi) + bsdf_alpha(bsdf)) +
       bsdf_lambert_sample(wo, u) + bsdf_ggx_sample_vndf(wo, 0.3f, u) * bsdf_ggx_lambda(wo, 0.3f) + vec3(BSDF_MIN_ALPHA);
  // pt_wave.h (layouts only)
  PtWave wave;
  wave.extendArgs = uvec4(PT_WAVE_GROUP, PT_QUEUE_TO_SHADE, PT_QUEUE_TO_EXTEND, i);
  PtPush push;
  push.slots = wave.extendArgs.w;
  t += float(push.slots + wave.extendArgs.x);
  // surface_types.h (layouts only)
  GpuSurfaceMaterial material;
  material.bsdf = bsdf;
  material.emission = vec3(PT_PATH_TEXELS);
  // light_tree.h
  GpuLightNode node;
  node.boxMin = vec3(-1.0f);
  node.boxMax = vec3(1.0f);
  node.power = material.emission.x;
  node.axis = vec3(0.0f, 0.0f, 1.0f);
  node.cosCone = 0.5f;
  node.child = LT_LEAF;
  t += lt_importance(node, wo + vec3(3.0f), wo) + lt_first_child_probability(1.0f, 2.0f) + material.bsdf.alpha;
  values[i] = vec4(s + wo, t + m + (picked ? 1.0f : 0.0f) + (dropped ? 2.0f : 0.0f) +
                   (rs_is_finite(back.W) ? back.W : 0.0f));
}
