// Unbiased ReSTIR with surfaces (issue 12 deliverable 4; notes/restir.md "Surfaces"): surface
// vertices in the reservoirs' paths, NEE and BSDF sampling at them, emissive triangles as light
// samples and as hits (MIS), the shift: by default the reconnection shift at the first surface
// vertex after the primary one (the vertices before it copied), with render.restir_shift copy
// every direction copied (failing where the copied ray's first event is of the other kind). Tier d: per-pixel Z-test and aggregate
// z-test against the CPU reference (which intersects with Embree itself), pairwise MIS and the
// generalised balance heuristic, with spatial reuse over a radius wide enough that neighbours'
// paths cross the ground's, the occluder's and the conductor's silhouettes. Each GPU sample is one frame of an
// independent run (support/restir_check.h), so the variances are honest. The tail past a short
// prefix: test_restir_surfaces_slow.cpp.
#include "support/gpu_fixture.h"
#include "support/grids.h"
#include "support/restir_check.h"
#include "support/scenes.h"

using namespace plume;

namespace {

class GpuRestirSurfaces : public test::GpuTest {};

}  // namespace

// Smoke over a diffuse ground under a sun and a sky: the smoke's shadow on the ground (shadow
// rays through the medium from surface vertices), the ground's light bounced into the smoke
// (medium vertices after surface vertices), the sky by BSDF sampling at the ground.
TEST_F(GpuRestirSurfaces, SmokeOverGroundMatchesReference) {
  test::expectRestirMatchesReference(ctx(), compiler(), test::smokeOverGroundScene(16, 3),
                                     test::makeNoiseGrid(32, 1.0 / 16, 3), 256, 4096, "smoke_over_ground");
}

// An occluder between the sun and the smoke (surface visibility on shadow rays) and a glossy
// conductor (GGX sampling and evaluation at surface vertices).
TEST_F(GpuRestirSurfaces, OccluderAndGlossyConductorMatchReference) {
  test::expectRestirMatchesReference(ctx(), compiler(), test::occluderAndConductorScene(16, 3),
                                     test::makeNoiseGrid(32, 1.0 / 16, 5), 256, 1024, "occluder_and_conductor");
}

// Emissive quads as the only lights: points on the emitters as light samples (area measure,
// cosine at the light, the alias table's choice) and emitters hit by sampled directions, combined
// by MIS (dropping the hits' weight doubles the image: mean ratio 1.96); emitters seen directly by
// camera rays; a back-facing quad that must stay dark. The low quad hangs 0.5 above the ground
// (the path tracer's test has it at 2 cm, where these run counts resolve only a 5% bias).
TEST_F(GpuRestirSurfaces, EmissiveQuadsAsTheOnlyLightsMatchReference) {
  test::expectRestirMatchesReference(ctx(), compiler(), test::emissiveQuadsScene(16, 3, 0.5f),
                                     test::makeNoiseGrid(32, 1.0 / 16, 7), 256, 4096, "emissive_quads");
}

// The same with one shadowed light sample a candidate vertex (render.restir_light_candidates 1)
// instead of light resampling: the candidates' weights then use the target's own light term
// (restir/candidates.glsl), so the two must agree on the emitters' MIS weight, which the target
// leaves out (restir/bridge.glsl rs_path_contribution). Can it fail: with the candidates' light
// term weighted by it and the target not (W then w_sum over a different function), mean ratio
// 0.980-0.982, aggregate z -4.1 (session 37).
TEST_F(GpuRestirSurfaces, EmissiveQuadsWithOneLightSampleAVertexMatchReference) {
  RestirOptions one = test::spatialReuse(shared::RS_MIS_PAIRWISE);
  one.lightCandidates = 1;
  test::expectRestirMatchesReference(ctx(), compiler(), test::emissiveQuadsScene(16, 3, 0.5f),
                                     test::makeNoiseGrid(32, 1.0 / 16, 7), 256, 4096,
                                     "emissive_quads_one_light_sample", {shared::RS_MIS_PAIRWISE}, one);
}

// The candidates' Russian roulette with surfaces: on the walk's throughput f / p, as the path
// tracer's (restir/candidates.glsl; a fixed probability, the medium's albedo, until session 38),
// from the first vertex on (render.rr_start_bounce 1) over four bounces among emissive quads, the
// dark ground and the smoke, so that most walks end by it and its probability enters the pdf of
// every candidate past the first vertex. Can it fail: with the probability left out of the pdf
// (the path's weight then too small by it) mean ratio 0.982, aggregate z -5.8 (correct: 1.000,
// |z| <= 0.17, worst pixel 2.88; 1024 runs, about 6 s).
TEST_F(GpuRestirSurfaces, RouletteOnTheThroughputMatchesReference) {
  Scene s = test::emissiveQuadsScene(16, 4, 0.5f);
  s.render.rrStartBounce = 1;
  test::expectRestirMatchesReference(ctx(), compiler(), s, test::makeNoiseGrid(32, 1.0 / 16, 7), 1024, 4096,
                                     "roulette_on_the_throughput", {shared::RS_MIS_PAIRWISE});
}

// The candidates' target of the selected path: p̂' (the value the candidates' resampling kept for
// it) times the mean field's transmittance along its segments, gathered while the walk went
// (restir/candidates.glsl; re-evaluated from the stored path until session 38), must be the target
// that reuse evaluates for that path: with a still camera the same-domain temporal pipeline reads
// each input's p̂ as stored where the general one evaluates it (rs_cross_targets), so their frames
// agree only if the two are one function. Emissive quads (light resampling, L = 2) in smoke 4x
// denser than the other scenes', where the segments' transmittance is far from 1; temporal and
// spatial reuse over 4 frames. Can it fail: with the segments' factor left out of the stored p̂
// (and of W, so that W p̂ stays right) the two pipelines differ by up to 4.5 (relative) in 519 of
// 600 lit channels; with the walk's whole product taken for the selected candidate's, 2.45 in 585
// of 597. Correct: 1.4e-6 (3.4e-7 when the candidates re-evaluated the target).
TEST_F(GpuRestirSurfaces, CandidatesTargetIsTheTargetReuseEvaluates) {
  RestirOptions same = test::spatialReuse(shared::RS_MIS_PAIRWISE);
  same.historyCap = 20;
  RestirOptions general = same;
  general.sameDomainTemporal = false;
  test::ExtremeCase c;
  c.name = "candidates_target";
  c.scene = test::emissiveQuadsScene(16, 3, 0.5f);
  c.scene.medium().densityScale *= 4.0f;
  c.grid = test::makeNoiseGrid(32, 1.0 / 16, 7);
  const Image a = test::runRestirCase(ctx(), compiler(), c, 2, same, 4).image;
  const Image b = test::runRestirCase(ctx(), compiler(), c, 2, general, 4).image;
  const auto [worst, lit] = test::relativeAgreement(a, b);
  std::printf("[restir] candidates' target against reuse's: worst relative difference %.3g over %zu lit channels\n",
              worst, lit);
  ASSERT_GT(lit, a.rgb.size() / 2) << "too few lit channels to compare";
  EXPECT_LT(worst, 1e-5) << "the stored target must be the one reuse evaluates, to rounding";
}

// Lamps seen directly (support/scenes.h lampsSeenDirectlyScene; most of the image): their
// reservoir of its own (restir/candidates.glsl rs_lamp_reservoir: 16 stratified camera rays as
// candidates, the previous frame's reservoir merged in by the generalised balance heuristic when
// the camera is still) beside the light paths' with spatial reuse. Three passes: (1) frame 3 of a
// still camera with temporal and spatial reuse, pairwise and GBH (frame 1 without a history,
// frames 2 and 3 with one); (2) one frame (the 16 candidates alone); (3) frame 3 of a still
// camera over an animated grid (frames 1 and 2 another grid, the last frame's history rendered
// with it, 3x denser), where the two inputs' targets differ. Can it fail: with the candidates'
// weight 0.7 instead of 1 every pass does (mean ratio 0.73-0.77, aggregate z -21 to -34); with
// the canonical sample's target in the history's domain taken as 0 where the grids differ (its
// MIS weight 1: the history's share counted twice) the animated pass reads 1.48-1.55 (z 42-45).
// Not resolved here: the still grid's shortcut (the history's stored target taken as its target
// now, RestirParams::lampSameVolume forced on) is nearly unbiased when the transmittance ratio of
// the two grids is the same over the part of a pixel a lamp covers, as it is for small lamps.
TEST_F(GpuRestirSurfaces, LampsSeenDirectlyMatchReference) {
  const Scene s = test::lampsSeenDirectlyScene(16, 3);
  const auto grid = test::makeNoiseGrid(32, 1.0 / 16, 7);
  RestirOptions reuse = test::spatialReuse(shared::RS_MIS_PAIRWISE);
  reuse.historyCap = 20;
  test::expectRestirMatchesReference(ctx(), compiler(), s, grid, 256, 16384, "lamps_seen_directly_history",
                                     {shared::RS_MIS_PAIRWISE, shared::RS_MIS_GBH}, reuse, 3);
  // A still view's long history (session 32): no spatial reuse where nothing changed, and a history
  // whose cap is longer there than the plain one (1 x M here, so frame 3's history holds
  // two frames' candidates only under restir_history_cap_static); the lamp reservoirs' too.
  RestirOptions still = reuse;
  still.roundsStatic = 0;
  still.historyCap = 1;
  still.historyCapStatic = 20;
  test::expectRestirMatchesReference(ctx(), compiler(), s, grid, 256, 16384, "lamps_seen_directly_static_history",
                                     {shared::RS_MIS_PAIRWISE}, still, 3);
  // 512 runs for the one-frame pass: with two spatial neighbours 128 runs left one pixel at z
  // -4.72 (512: -2.84; notes/restir.md "Session 25").
  test::expectRestirMatchesReference(ctx(), compiler(), s, grid, 512, 16384, "lamps_seen_directly_one_frame",
                                     {shared::RS_MIS_PAIRWISE});
  // The pieces for some pixels and their rectangles for the others (RestirOptions::lampPieceWords:
  // the device's limit reached), the history merging the two.
  RestirOptions someInRects = reuse;
  someInRects.lampPieceWords = 8 * 24;
  test::expectRestirMatchesReference(ctx(), compiler(), s, grid, 256, 16384, "lamps_seen_directly_some_in_rectangles",
                                     {shared::RS_MIS_PAIRWISE}, someInRects, 3);
  // A denser grid before: the lamps behind the cloud are dimmer in the history's target.
  auto before = test::makeNoiseGrid(32, 1.0 / 16, 8);
  for (auto it = before->beginValueOn(); it; ++it) it.setValue(3.0f * *it);
  test::expectRestirMatchesReference(ctx(), compiler(), s, grid, 256, 16384, "lamps_seen_directly_animated",
                                     {shared::RS_MIS_PAIRWISE}, reuse, 3, before);
}

// The lamps' share of each pixel computed, not counted (RestirOptions::lampTriangles, the default:
// restir/candidates.glsl rs_lamp_triangle_candidates draws the lamp reservoir's 16 rays on the
// pieces of the pixel that each emitter's projection covers, chosen by Le times their area, where
// RestirOptions::lampTriangles false draws them on the rectangle that bounds those projections).
// With the lamps unoccluded, the candidates' weights are all S / 16 where they see their emitter,
// so what is left of a lamp pixel's noise is the smoke's transmittance along the selected ray and
// the light paths'. One-frame runs of the canonical candidates alone (no reuse) over the lamps of
// LampsSeenDirectlyMatchReference (4 cm quads, under a pixel wide): the variance of the mean summed
// over the image, pieces against rectangles. (Their expectation is the Z-tests': the test above
// runs the pieces.)
TEST_F(GpuRestirSurfaces, LampPiecesLeaveLessNoiseThanRaysInTheirRectangle) {
  test::ExtremeCase c;
  c.name = "lamp_pieces";
  c.scene = test::lampsSeenDirectlyScene(16, 3);
  c.grid = test::makeNoiseGrid(32, 1.0 / 16, 7);
  RestirOptions o;
  o.rounds = 0;
  o.historyCap = 0;
  double variance[2] = {0.0, 0.0};
  for (const bool pieces : {true, false}) {
    o.lampTriangles = pieces;
    const test::EstimatorRun run = test::runRestirCase(ctx(), compiler(), c, 128, o, 1);
    EXPECT_EQ(run.nonFinite, 0u);
    for (float v : run.image.var) variance[pieces ? 0 : 1] += double(v);
  }
  std::printf("[restir surfaces] lamps seen directly, one frame without reuse: the image's summed variance "
              "%.4g on the pieces, %.4g in the rectangles (%.1fx)\n",
              variance[0], variance[1], variance[1] / variance[0]);
  // (Measured: 6.3x less.)
  EXPECT_LT(3.0 * variance[0], variance[1]) << "the pieces must leave less of the lamps' noise";
}

// A moving camera over surfaces: temporal reuse between frames whose camera rays differ (the
// history pixel reprojected, every cross-domain target evaluated: the surface vertices re-traced,
// the reconnection to the stored point from a moved primary vertex, the lamp reservoir without a
// history), then spatial reuse; frame 4 of a camera that moves 0.04 per frame (about a pixel),
// against the reference of that pose. Emissive quads as the only lights, and the sun over the
// ground. (Session 16: no such test existed; the city's moving-camera fireflies, notes/city.md,
// made the question. It passes: worst pixel |z| <= 4.2, aggregate |z| <= 2. The worst pixel, at
// the edge of the back-facing quad, reads z 3.9 with a still camera at the same pose too, and
// failed at 4.9 against a 4096-spp reference whose value there was one rare path: hence 16384.
// Can it fail: a temporal shift that took a surface primary vertex at its stored distance instead
// of re-tracing it read mean ratio 0.45-0.83, notes/session-16-primary-shift-prototype.diff.)
TEST_F(GpuRestirSurfaces, MovingCameraMatchesReferenceOfItsLastPose) {
  RestirOptions o = test::spatialReuse(shared::RS_MIS_PAIRWISE);
  o.historyCap = 20;
  // Four light samples a candidate vertex in the frames whose camera moved (two in the first,
  // which has no history): the candidates' pipeline changes between frames, as the bundled city's
  // does (render.restir_light_candidates_moving).
  o.lightCandidatesMoving = 4;
  for (Scene base : {test::emissiveQuadsScene(16, 3, 0.5f), test::smokeOverGroundScene(16, 3)}) {
    const Scene s = test::cameraMovedBy(base, 4, {0.12f, 0.04f, 0.0f});
    const bool emitters = s.lights.empty();
    test::expectRestirMatchesReference(ctx(), compiler(), s, test::makeNoiseGrid(32, 1.0 / 16, 7), 256, 16384,
                                       emitters ? "moving_emissive_quads" : "moving_smoke_over_ground",
                                       {shared::RS_MIS_PAIRWISE, shared::RS_MIS_GBH}, o, 4);
  }
}

// render.restir_light_candidates_moving takes effect only in frames whose camera moved: with a
// still camera the image is the plain setting's to the bit, with a moving one it differs (the
// moving pipeline's candidates resample another number of light samples a vertex).
TEST_F(GpuRestirSurfaces, LightCandidatesWhileMovingActOnlyWhenTheCameraMoves) {
  RestirOptions plain = test::spatialReuse(shared::RS_MIS_PAIRWISE);
  plain.historyCap = 20;
  RestirOptions more = plain;
  more.lightCandidatesMoving = 4;
  test::ExtremeCase c;
  c.name = "light_candidates_moving";
  c.scene = test::emissiveQuadsScene(16, 3, 0.5f);
  c.grid = test::makeNoiseGrid(32, 1.0 / 16, 7);
  auto differing = [&](const Scene& s) {
    c.scene = s;
    const Image a = test::runRestirCase(ctx(), compiler(), c, 2, plain, 3).image;
    const Image b = test::runRestirCase(ctx(), compiler(), c, 2, more, 3).image;
    size_t n = 0;
    for (size_t i = 0; i + 2 < a.rgb.size(); i += 3) {
      n += a.rgb[i] != b.rgb[i] || a.rgb[i + 1] != b.rgb[i + 1] || a.rgb[i + 2] != b.rgb[i + 2] ? 1 : 0;
    }
    return n;
  };
  const Scene still = c.scene;
  const Scene moving = test::cameraMovedBy(still, 3, {0.12f, 0.04f, 0.0f});
  EXPECT_EQ(differing(still), 0u) << "a still camera must keep restir_light_candidates";
  EXPECT_GT(differing(moving), 256u / 4u) << "a moving camera's frames must use restir_light_candidates_moving";
}

// A black quad in front of the left half of the smoke: spatial reuse must not bring the smoke's
// light into the pixels that see the quad. A neighbour's medium vertex copied into such a pixel
// lies behind the quad, where the shift must fail (f = 0); without that failure (no visibility
// test on a copied medium vertex) the per-pixel Z-test fails at the quad's edge (worst z 6.9
// pairwise, 6.5 GBH).
TEST_F(GpuRestirSurfaces, ReuseDoesNotLeakLightAcrossAnOccludersEdge) {
  Scene s = test::smokeOverGroundScene(16, 2);
  Surface quad = test::planeSurface({0.6f, 0.9f, 2.3f}, {0.0f, 0.0f, 1.0f}, {0.9f, 2.4f});
  quad.albedo = glm::vec3(0.0f);
  s.surfaces.push_back(quad);
  test::expectRestirMatchesReference(ctx(), compiler(), s, test::makeNoiseGrid(32, 1.0 / 16, 3), 64, 256,
                                     "occluder_edge");
}

// The reconnection shift (render.restir_shift reconnect, the default) and the copy shift on a
// scene made for the first: the ground beside a glowing wall reconnects to it over distances and
// angles that differ by large factors between neighbours, and a black fin hides the wall from
// the ground on its other side. Without the visibility test of the reconnected segment the
// per-pixel test fails (worst pixel z 5.4 left of the fin). Measuring the reconnection vertex in
// solid angle instead of area (its cosine and squared-distance factor dropped in the candidates
// and the target alike: the shift's Jacobian missing) is not resolved here (mean ratio 1.0020
// either way): with MIS weights of the balance form the error of a missing factor J is
// (1 - J)/(1 + J) of the pair's share, which cancels between J and 1/J over neighbours drawn
// symmetrically (notes/restir.md "The reconnection shift"); the next test resolves it. The factor
// in one place only fails at once (the candidates without it: mean ratio 456). 1024 runs since
// session 30 (256 before): the candidates' light samples are resampled without their shadow ray
// (restir/candidates.glsl), so in the fin's shadow most selections are blocked and the rest
// weigh more; at 256 runs one pixel there read z -7.2 (1024: worst pixel 3.27, resolving 0.48%
// instead of 0.81%). With the selected sample's segment transmittances left out of W (a
// sabotage) it fails: mean ratio 0.98, aggregate z -14.9.
TEST_F(GpuRestirSurfaces, ReconnectionBetweenWallsMatchesReference) {
  const Scene s = test::wallsAndFinScene(16, 3);
  const auto grid = test::makeNoiseGrid(32, 1.0 / 16, 11);
  for (bool reconnect : {true, false}) {
    RestirOptions o = test::spatialReuse(shared::RS_MIS_PAIRWISE);
    o.reconnect = reconnect;
    test::expectRestirMatchesReference(ctx(), compiler(), s, grid, 1024, 4096, "walls_and_fin", {shared::RS_MIS_PAIRWISE},
                                       o);
  }
}

// The reconnection shift's Jacobian: every pixel reuses exactly one neighbour, the pixel four rows
// up (RestirOptions::fixedNeighbourX/Y; unbiased, since the choice does not depend on the
// samples), on a ground lit mostly by a wall's bounce (support/scenes.h sunlitWallScene), so that
// the paths camera -> ground -> wall -> sun reconnect at the wall with J far from 1, always on the
// same side. The offset is never mirrored, so a wrong Jacobian no longer cancels as it does
// between the disk's symmetric neighbours. With the Jacobian dropped (rs_reconnect_area_factor
// returning 1, in the candidates and the target alike) both kinds fail: pairwise mean ratio
// 1.0114, aggregate z 4.9, worst pixel z 4.9; GBH 1.0201, z 8.2, worst pixel 8.6 (correct: 1.0019
// and 1.0012, z <= 0.86, worst pixel 3.2). About 35 s.
TEST_F(GpuRestirSurfaces, ReconnectionJacobianWithAFixedNeighbour) {
  const Scene s = test::sunlitWallScene(16, 3);
  const auto grid = test::makeNoiseGrid(32, 1.0 / 16, 11);
  RestirOptions o = test::spatialReuse(shared::RS_MIS_PAIRWISE);
  o.fixedNeighbourY = -4;  // four rows up: the neighbour's ground point is nearer the wall
  test::expectRestirMatchesReference(ctx(), compiler(), s, grid, 512, 8192, "walls_fixed_neighbour",
                                     {shared::RS_MIS_PAIRWISE, shared::RS_MIS_GBH}, o);
}
