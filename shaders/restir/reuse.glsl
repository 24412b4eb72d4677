// The one reuse step (DESIGN §4.2 steps 4-6), shared by temporal and spatial reuse: the
// canonical reservoir (index 0, always included) and neighbours, each with its own domain, are
// resampled into the canonical domain with the volume-aware shift (the path's coordinates
// copied, so Jacobian 1; a shift onto zero density gives p̂ = 0, a failure, and the MIS weights
// see the same zero from either side) and MIS weights from shared/restir_types.h:
//   w_s = m_s(y_s) * p̂_c(y_s) * W_s,   W = Σ w / p̂_c(Y)   (GRIS Eq. 3.2-3.3).
// Requires restir/bridge.glsl.
#ifndef PLUME_RESTIR_REUSE_GLSL
#define PLUME_RESTIR_REUSE_GLSL

const uint RS_MAX_INPUTS = RS_MAX_NEIGHBOURS + 1u;

struct RsInputs {
  uint count;                       // 1 + neighbours
  uint set[RS_MAX_INPUTS];          // reservoir set of each input
  uint pixel[RS_MAX_INPUTS];        // pixel index of each input
  RsDomain domain[RS_MAX_INPUTS];   // its domain (the pixel's ray in its frame, that frame's volume)
  RsReservoir res[RS_MAX_INPUTS];   // its reservoir (confidence already capped)
  bool sameDomain;                  // inputs 0 and 1 share one domain (still camera and volume)
};

// p̂ of input s's path in input j's domain (the stored value when j == s or when both share
// the domain: the same deterministic function of the same arguments).
// The inputs of this invocation's reuse step: one shader-private variable, not a by-value
// argument (a copy of the whole array per call is what a by-value struct compiles to).
RsInputs in_;

float rs_target_in(uint s, uint j) {
  if (j == s || (in_.sameDomain && s <= 1u && j <= 1u)) return in_.res[s].p_hat;
  return rs_target(in_.domain[j], in_.set[s], in_.pixel[s]);
}

// Resamples the inputs into input 0's domain; writes the reservoir and the selected path to
// (outSet, outPixel). misKind: RS_MIS_PAIRWISE, RS_MIS_GBH or RS_MIS_BIASED.
void rs_reuse(uint misKind, uint outSet, uint outPixel, inout RngState rng) {
  float Msum = 0.0f;
  for (uint s = 0u; s < in_.count; ++s) Msum += in_.res[s].M;
  float Mc = in_.res[0].M;
  RsReservoir out_ = rs_empty();
  uint selected = RS_MAX_INPUTS;
  for (uint s = 0u; s < in_.count; ++s) {
    RsReservoir rs_ = in_.res[s];
    bool hasSample = rs_.W > 0.0f && rsPaths[rs_slot(in_.set[s], in_.pixel[s])].info.x > 0u;
    float phC = 0.0f;
    float m = 0.0f;
    if (hasSample) {
      phC = rs_target_in(s, 0u);
      if (misKind == RS_MIS_BIASED) {
        m = rs_.M / Msum;
      } else if (misKind == RS_MIS_GBH) {
        float denom = 0.0f;
        for (uint j = 0u; j < in_.count; ++j) {
          denom += in_.res[j].M * (j == 0u ? phC : rs_target_in(s, j));
        }
        m = rs_gbh(rs_.M, rs_.p_hat, denom);
      } else if (s == 0u) {
        m = Mc / Msum;
        for (uint i = 1u; i < in_.count; ++i) {
          m += rs_pairwise_canonical_term(in_.res[i].M, rs_target_in(0u, i), Mc, phC, Msum);
        }
      } else {
        m = rs_pairwise_neighbour(rs_.M, rs_.p_hat, Mc, phC, Msum);
      }
    }
    if (rs_merge(out_, rs_, phC, 1.0f, m, rng_float(rng))) selected = s;
  }
  rs_finalize(out_);
  if (selected < RS_MAX_INPUTS && out_.W > 0.0f) {
    rs_copy_path(in_.set[selected], in_.pixel[selected], outSet, outPixel);
  } else {
    out_.w_sum = 0.0f;
    out_.p_hat = 0.0f;
    out_.W = 0.0f;
    rsPaths[rs_slot(outSet, outPixel)].info.x = 0u;
  }
  rs_store(outSet, outPixel, out_);
}

// The history pixel for `pixel` (DESIGN §4.2 step 5): the point at the fixed reprojection depth
// along the pixel centre's ray, projected with the previous camera. Depends on the pixel and the
// cameras only, never on a sample. False when it falls outside the previous image.
bool rs_reproject(uvec2 pixel, out uvec2 prevPixel) {
  prevPixel = pixel;
  float sx = (2.0f * (float(pixel.x) + 0.5f) / float(frame.image.x) - 1.0f) * frame.camPosition.w * frame.camForward.w;
  float sy = (1.0f - 2.0f * (float(pixel.y) + 0.5f) / float(frame.image.y)) * frame.camPosition.w;
  vec3 dir = normalize(frame.camForward.xyz + sx * frame.camRight.xyz + sy * frame.camUp.xyz);
  vec3 p = frame.camPosition.xyz + rsp.configF.z * dir - rsp.prevCamPosition.xyz;
  float z = dot(p, rsp.prevCamForward.xyz);
  if (!(z > 0.0f)) return false;
  float px = dot(p, rsp.prevCamRight.xyz) / (z * rsp.prevCamPosition.w * rsp.prevCamForward.w);
  float py = dot(p, rsp.prevCamUp.xyz) / (z * rsp.prevCamPosition.w);
  vec2 f = vec2((px + 1.0f) * 0.5f * float(frame.image.x), (1.0f - py) * 0.5f * float(frame.image.y));
  if (!(f.x >= 0.0f && f.y >= 0.0f && f.x < float(frame.image.x) && f.y < float(frame.image.y))) return false;
  prevPixel = uvec2(f);
  return true;
}

#endif
