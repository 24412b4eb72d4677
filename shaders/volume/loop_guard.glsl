// The driver-loop-limit probe. llvmpipe (Mesa's lavapipe, Plume's baseline device) guards every
// shader against endless loops with one counter per invocation (per SIMD group of 8 lanes) that
// all loops share: gallivm's LP_MAX_TGSI_LOOP_ITERATIONS = 65535 back-edges, counted for the
// group, over the whole dispatch. Past it, every loop exits after one iteration, without an
// error: walks end early, transmittances stay too high, collisions are missed, and the image is
// biased (measured: a dense albedo-0.99 slab at 16 spp per dispatch read 12% low, and the mean
// depended on the majorant; notes/extreme.md). Once spent, the budget stays spent, so one probe
// at the end of a pass tells whether any loop of the invocation was cut: a loop of `probe`
// iterations (frame.loopProbe = 2, from the host, so that no compiler can unroll it) that runs
// once.
// Counted in volCounters[VOL_COUNTER_LOOP_LIMIT] and reported by the host, never silent. On other
// devices the probe always runs twice and costs nothing measurable.
// Requires volume/bindings.glsl. Tested by tests/test_loop_guard.cpp.
#ifndef PLUME_VOLUME_LOOP_GUARD_GLSL
#define PLUME_VOLUME_LOOP_GUARD_GLSL

const uint VOL_COUNTER_LOOP_LIMIT = 1u;  // volCounters[1]: invocations whose loops the driver cut

void loop_guard_check(uint probe) {
  uint n = 0u;
  for (uint i = 0u; i < probe; ++i) n += 1u;
  if (n != probe) atomicAdd(volCounters[VOL_COUNTER_LOOP_LIMIT], 1u);
}

#endif
