// Which pixels a Monte Carlo reference resolves, for the per-pixel Z-test (reference_check.h).
//
// Every path that reaches the camera starts with a collision on a camera ray of its pixel, so a
// reference of N samples per pixel has about N·P samples that are not zero there, with
//   P = E[1 - exp(-tau)]   over the pixel's camera rays (box filter), tau their optical depth,
// the pixel's first-collision probability. With surfaces a path's first vertex is the nearer of
// the medium's collision and the first surface, so a camera ray that meets a surface counts 1.
// Where N·P is small the reference is nearly always exactly 0 with a variance estimate of 0,
// while its true value is positive: an estimator that does reach the pixel (reuse brings paths
// into it from its neighbours) is then "significantly" above the reference however right it
// is, and the more so the more runs it is given. This is
// what failed the ReSTIR tests on the Blender fire (notes/restir.md, "Thin wisps"): Mantaflow's
// wisps of density 1e-6 give P of 1e-6 to 1e-10 at 16², far beyond any affordable N.
//
// The map is computed from the camera, the OpenVDB grid and the surfaces alone (never from an
// image), by marching a grid of rays per pixel with the trilinear sampler the reference uses.
#pragma once

#include "scene/scene.h"

#include <openvdb/openvdb.h>

#include <cstdint>
#include <vector>

namespace plume::test {

// A pixel whose reference rests on fewer expected non-zero samples than this is left out of the
// per-pixel test: a variance estimated from fewer samples is too unreliable for the Šidák tails
// (core/stats.h: "use n >= ~100").
constexpr double kMinReferenceCollisions = 100.0;

enum class PixelResolution : uint8_t {
  Empty,       // no density on or near its camera rays: both images must be 0 (kept in the test)
  Resolved,    // N·P >= the bound (kept in the test)
  Unresolved,  // 0 < N·P < the bound (left out of the per-pixel test; the aggregate keeps it)
};

struct ResolutionMap {
  int width = 0, height = 0;
  std::vector<PixelResolution> pixels;      // row-major, row 0 at the top
  std::vector<double> collisionProbability;  // P per pixel
  int count(PixelResolution r) const;
  std::vector<bool> unresolvedMask() const;  // for ReferenceCheckOptions::unresolved
};

// The map of a reference of `spp` samples per pixel of `scene` (camera at `frame`, media[0]'s
// density scale) on `density`. `raysPerAxis`² rays estimate P; a pixel is Empty only if no ray
// of a grid over its square grown by half a pixel on every side meets density.
ResolutionMap referenceResolution(const Scene& scene, const openvdb::FloatGrid& density, int spp, int frame = 1,
                                  int raysPerAxis = 16, double minCollisions = kMinReferenceCollisions);

}  // namespace plume::test
