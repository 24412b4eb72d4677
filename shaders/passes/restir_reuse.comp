// ReSTIR passes 2 and 3 (DESIGN §4.2 steps 5-6): temporal reuse (push.sets.w ==
// RS_PASS_TEMPORAL: the canonical set push.sets.x and the history set push.sets.y at the
// reprojected pixel, confidence capped) or one spatial round (k neighbours of set push.sets.x
// within the radius, drawn from the pixel and the round only). Output: set push.sets.z.
#version 450
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 8, local_size_y = 8) in;

#include "../restir/bindings.glsl"
#include "../volume/volume.glsl"
#include "../restir/coarse.glsl"
#include "../restir/bridge.glsl"
#include "../restir/reuse.glsl"

void main() {
  uvec2 pixel = gl_GlobalInvocationID.xy;
  if (pixel.x >= frame.image.x || pixel.y >= frame.image.y) return;
  uint index = pixel.y * frame.image.x + pixel.x;
  in_.count = 1u;
  in_.sameDomain = false;
  in_.set[0] = push.sets.x;
  in_.pixel[0] = index;
  in_.domain[0] = rs_current_domain(pixel);
  in_.res[0] = rs_load(push.sets.x, index);
  bool temporal = push.sets.w == RS_PASS_TEMPORAL;
  uint stream = temporal ? RNG_STREAM_TEMPORAL : RNG_STREAM_SPATIAL + (push.misc.x << 8u);
  RngState rng = rng_init(pixel, frame.seeds.y, stream, frame.seeds.x);
  if (temporal) {
    uvec2 q;
    if (rsp.frames.z != 0u && rs_reproject(pixel, q)) {
      uint qi = q.y * frame.image.x + q.x;
      in_.set[1] = push.sets.y;
      in_.pixel[1] = qi;
      in_.domain[1] = rs_previous_domain(q);
      in_.sameDomain = rsp.misc.y != 0u && qi == index;
      in_.res[1] = rs_load(push.sets.y, qi);
      rs_cap_confidence(in_.res[1], rsp.configF.y * in_.res[0].M);
      in_.count = 2u;
    }
  } else {
    for (uint i = 0u; i < rsp.config.y; ++i) {
      vec2 u = rng_float2(rng);  // neighbour offsets: uniform in the disk, independent of samples
      float radius = rsp.configF.x * sqrt(u.x);
      ivec2 q = ivec2(pixel) + ivec2(round(radius * vec2(cos(2.0f * PLUME_PI * u.y), sin(2.0f * PLUME_PI * u.y))));
      if (any(lessThan(q, ivec2(0))) || q.x >= int(frame.image.x) || q.y >= int(frame.image.y)) continue;
      if (q == ivec2(pixel)) continue;
      uint qi = uint(q.y) * frame.image.x + uint(q.x);
      uint k = in_.count++;
      in_.set[k] = push.sets.x;
      in_.pixel[k] = qi;
      in_.domain[k] = rs_current_domain(uvec2(q));
      in_.res[k] = rs_load(push.sets.x, qi);
    }
  }
  rs_reuse(rsp.config.z, push.sets.z, index, rng);
}
