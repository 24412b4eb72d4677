// The targets' colour weights (DESIGN §4.2): a domain's target is p̂ = dot(k, f) for the RGB
// contribution f of a path, k the weights of the domain's pixel. With k = (1, 1, 1) / 3 (the
// luminance; render.restir_target luminance) a pixel whose light mixes colours — a fire's
// orange emission and the blue sky its smoke scatters — selects a path in proportion to its
// luminance, so the rare blue path of an orange pixel lands with a weight that is a small error
// in luminance and a large one in blue: the relative error of each channel, which relMSE and the
// eye see, is not what the target balanced. Weighing each channel by the inverse of the pixel's
// own colour Ê (the 3x3 mean of an estimate of the pixel's radiance) balances them:
//   k_c = (Ê_r + Ê_g + Ê_b) / (9 max(Ê_c, floor)),   floor = RS_COLOUR_FLOOR max_c Ê_c,
// (1, 1, 1) / 3 for a grey pixel, the luminance's scale (dot(k, Ê) = mean of Ê where no channel
// is floored), the weights' ratio at most 1 / RS_COLOUR_FLOOR.
// Any positive weights that do not depend on the samples being resampled keep every estimator
// unbiased (GRIS: a target need only be positive where the integrand is, and may differ between
// domains). Ê therefore comes from walks of its own (a random stream no reservoir draws from:
// the path tracer's estimate of the pixel, truncated at RS_TAIL_SEGMENTS segments, which is a
// choice of weights, not a bias): weights taken from the image the reservoirs shaded were
// correlated with the history they then resampled, and read 0.7% dark under coloured lights
// (notes/restir.md "Session 39"). And each domain's target must be one function wherever it is
// evaluated: a pixel's weights change only in frames where the host also runs the general
// temporal pipeline (Restir::fillFrame), which evaluates the history's domain with the history's
// weights (RestirParams::colourHistorySet).
#ifndef PLUME_RESTIR_COLOUR_GLSL
#define PLUME_RESTIR_COLOUR_GLSL

#ifndef PLUME_RS_COLOUR_TARGET
#define PLUME_RS_COLOUR_TARGET 1
#endif
#ifndef RS_COLOUR_FLOOR
#define RS_COLOUR_FLOOR (1.0f / 16.0f)
#endif

// One walk's estimate of the pixel's radiance, into the pixel's estimate slot: the mean of the
// last `memory` walks' (about: a running mean whose count stops there; 0: this walk alone).
void rs_colour_estimate(uvec2 pixel, uint index, float memory) {
  RngState rng = rng_init(pixel, frame.frameKey, RNG_STREAM_COLOUR, frame.seed);
  RsTail s = rs_tail_start(rs_current_domain(pixel), vec3(0.0f), rng);
  for (uint n = 0u; n < RS_TAIL_SEGMENTS; ++n) {
    if (!rs_tail_segment(s, rng, 0u, 0u, false)) break;
  }
  vec3 L = rs_is_finite(s.L.x + s.L.y + s.L.z) ? max(s.L, vec3(0.0f)) : vec3(0.0f);
  uint slot = rs_colour_slot(RS_COLOUR_ESTIMATE, index);
  vec4 e = memory > 0.0f ? rs_state(slot) : vec4(0.0f);
  float n = min(e.w, memory) + 1.0f;
  rs_set_state(slot, vec4(e.rgb + (L - e.rgb) / n, n));
}

// The weights of a pixel from its neighbourhood's estimates (rs_colour_estimate).
vec3 rs_colour_weights(uvec2 pixel) {
  const vec3 grey = vec3(1.0f / 3.0f);
#if PLUME_RS_COLOUR_TARGET
  vec3 sum = vec3(0.0f);
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      ivec2 q = ivec2(pixel) + ivec2(dx, dy);
      if (any(lessThan(q, ivec2(0))) || q.x >= int(frame.size.x) || q.y >= int(frame.size.y)) continue;
      sum += rs_state(rs_colour_slot(RS_COLOUR_ESTIMATE, uint(q.y) * frame.size.x + uint(q.x))).rgb;
    }
  }
  float top = max(max(sum.x, sum.y), sum.z);
  if (!(top > 0.0f) || !rs_is_finite(top)) return grey;
  vec3 floored = max(sum, vec3(RS_COLOUR_FLOOR * top));
  return vec3((floored.x + floored.y + floored.z) * (1.0f / 9.0f)) / floored;
#else
  return grey;
#endif
}

#endif
