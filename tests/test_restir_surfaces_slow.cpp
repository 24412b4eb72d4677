// ReSTIR with surfaces, the longer checks (label slow; the fast ones:
// test_restir_surfaces.cpp).
#include "support/gpu_fixture.h"
#include "support/grids.h"
#include "support/restir_check.h"
#include "support/scenes.h"

using namespace plume;

namespace {

class GpuRestirSurfacesSlow : public test::GpuTest {};

} // namespace

// Reservoirs holding one vertex (render.restir_prefix 1), so the tail
// (restir/shade.glsl) path-traces vertices 2 and 3: surface vertices, BSDF
// sampling, the emitters' light samples and hits with the reservoirs' MIS
// weights, each path length counted once by one of the two. The tail's paths
// are heavy-tailed near the quads: with 256 runs one pixel's variance came out
// too small (z -6.5 against a 4096-spp reference, the aggregate at 0.9946, z
// -0.9); 1024 runs against 16384 spp pass (worst z -3.1, aggregate 0.9945, z
// -1.75, resolving 1.1%). About 45 s.
TEST_F(GpuRestirSurfacesSlow, TailPastAOneVertexPrefixMatchesReference) {
  RestirOptions prefixOne = test::spatialReuse(shared::RS_MIS_PAIRWISE);
  prefixOne.prefix = 1;
  test::expectRestirMatchesReference(
      ctx(), compiler(), test::emissiveQuadsScene(16, 3, 0.5f),
      test::makeNoiseGrid(32, 1.0 / 16, 7), 1024, 16384, "emissive_quads_tail",
      {shared::RS_MIS_PAIRWISE}, prefixOne);
}
