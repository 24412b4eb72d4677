// Final shading (DESIGN §4.2 step 7): the selected path evaluated once with unbiased
// transmittance (residual ratio tracking on the fine grid, every segment and the light ray) times
// W = w_sum / p̂(Y); plus the environment seen directly through the camera ray (also by residual
// ratio tracking), which no reservoir path covers. Requires restir/bridge.glsl.
#ifndef PLUME_RESTIR_SHADE_GLSL
#define PLUME_RESTIR_SHADE_GLSL

vec3 rs_shade(uvec2 pixel, uint pixelIndex, uint set) {
  RsDomain D = rs_current_domain(pixel);
  RngState rng = rng_init(pixel, frame.seeds.y, RNG_STREAM_SHADING, frame.seeds.x);
  RsReservoir r = rs_load(set, pixelIndex);
  vec3 L = vec3(0.0f);
  if (r.W > 0.0f) L += r.W * rs_path_contribution(D, set, pixelIndex, true, rng);
#ifdef PLUME_HAS_ENV
  vec3 env = vec3(0.0f);
  for (uint i = 0u; i < rsp.frames.w; ++i) {
    if (uint(lights[i].params.x) == LIGHT_ENVIRONMENT) env += lights[i].emission.rgb;
  }
  L += env * rs_residual_tr(D.origin, rs_domain_dir(D, rng_float2(rng)), DDA_INF, rng);
#endif
  return L;
}

#endif
