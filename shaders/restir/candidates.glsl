// Candidate paths (DESIGN §4.2 step 1). M random walks per pixel, each from its own uniform
// position (u, v) in the pixel: each vertex's distance comes from coarse tracking in the mean
// field (pdf sigma_c exp(-tau_c), closed form; restir/coarse.glsl), each further direction from HG
// sampling, and every vertex ends one candidate with a light chosen in proportion to its
// estimated power (render/restir.cpp restirLights). The candidate ending at vertex j of walk m
// with light l is the path
// (u, v, t1, w2, t2, ..., w_j, t_j, l, light sample) with source pdf
//   p(y) = prod_i sigma_c(x_i) exp(-tau_i) * prod_{i>=2} phase_i * prod q (Russian roulette)
//          * p_light,
// and only "vertex j of some walk, light l" can produce it, so the M walks give it the MIS
// weight 1/M (GRIS allows candidates of one walk to be dependent: only marginals matter).
// The reservoir's confidence is M. Requires restir/bridge.glsl.
#ifndef PLUME_RESTIR_CANDIDATES_GLSL
#define PLUME_RESTIR_CANDIDATES_GLSL

void rs_generate_candidates(uvec2 pixel, uint pixelIndex, uint outSet) {
  RsDomain D = rs_current_domain(pixel);
  RngState rng = rng_init(pixel, frame.seeds.y, RNG_STREAM_CANDIDATES, frame.seeds.x);
  uint M = rsp.config.x;
  float invM = 1.0f / float(M);
  uint maxVertices = min(frame.image.w, RS_MAX_VERTICES);
  float g = frame.albedo.w;
  float q = min(1.0f, plume_max3(frame.albedo.rgb));
  uint base = rs_bounce_base(outSet, pixelIndex);
  RsReservoir r = rs_empty();
  RsPathHead head;
  head.geo = vec4(0.0f);
  head.info = uvec4(0u);
  vec4 walk[RS_MAX_VERTICES - 1u];
  for (uint m = 0u; m < M; ++m) {
    uint uv = rs_pack_uv(rng_float2(rng));  // the sub-pixel position: pdf 1 on the pixel
    vec3 x = D.origin;
    vec3 w = rs_domain_dir(D, rs_unpack_uv(uv));
    vec3 f = vec3(1.0f);  // prefix of f_D with coarse transmittance (the target's)
    float pdf = 1.0f;     // prefix of the source pdf
    float t1 = 0.0f;
    uint keep = 0u;  // vertices of this walk's selected candidate (0: none): copied when the walk ends
    for (uint j = 1u; j <= maxVertices; ++j) {
      float t;
      float sigmaC;
      float tau;
      if (!rs_coarse_sample(x, w, DDA_INF, rng_float(rng), t, sigmaC, tau)) break;
      float trTarget = exp(-min(tau, RS_MAX_TAU));  // the target's transmittance (same field)
      x += t * w;
      float sigma = rsv_sigma_t(0u, x);
      if (!(sigma > 0.0f)) break;  // f = 0 for this path and every extension of it
      pdf *= sigmaC * exp(-tau);   // the sampling field's free-flight pdf
      f *= trTarget * sigma * frame.albedo.rgb;
      if (j == 1u) {
        t1 = t;
      } else {
        walk[j - 2u] = vec4(w, t);
      }
      uvec4 h = rng_next4(rng);
      uint light;
      vec2 ls;
      float pl = rs_sample_light(w, g, vec3(rng_to_float(h.x), rng_to_float(h.y), rng_to_float(h.z)), light, ls);
      if (pl > 0.0f) {
        float ph = rs_luminance(f * rs_light_term(0u, light, ls, x, w, false, rng));
        float weight = invM * ph / (pdf * pl);
        if (rs_update(r, weight, ph, 0.0f, rng_to_float(h.w))) {
          head.geo = vec4(t1, ls, 0.0f);
          head.info = uvec4(j, light, 0u, uv);
          keep = j;
        }
      }
      if (j == maxVertices) break;
      if (j >= frame.seeds.w) {  // Russian roulette with a fixed probability: part of the pdf
        if (rng_float(rng) >= q) break;
        pdf *= q;
      }
      vec3 wNext = ph_hg_sample(w, g, rng_float2(rng));
      float phase = ph_hg(dot(w, wNext), g);
      pdf *= phase;
      f *= phase;
      w = wNext;
    }
    for (uint i = 0u; i + 2u <= keep; ++i) rsBounces[base + i] = walk[i];
  }
  r.M = float(M);
  rs_finalize(r);
  if (r.W <= 0.0f) head.info.x = 0u;
  rs_store(outSet, pixelIndex, r);
  rsPaths[rs_slot(outSet, pixelIndex)] = head;
}

#endif
