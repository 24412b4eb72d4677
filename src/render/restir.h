// Volumetric ReSTIR on the GPU (DESIGN §4.2): per frame, candidates -> temporal reuse ->
// spatial reuse x R -> final shading (-> its tail), compute passes (shaders/passes/restir_*.comp)
// over three reservoir sets that rotate (the last frame's final set is the history; three more
// where an emitting medium's emission paths have their own reservoir class). Candidates
// and the tail are dispatched several times, each dispatch a bounded share of the work
// (lavapipe's loop budget: notes/restir.md "Bounded work per dispatch"). The host only
// fills parameter blocks and picks sets; all reservoir arithmetic lives in the shaders
// (shared/reservoir.h, shared/restir_types.h, restir/*.glsl).
//
// Modes: "restir" (unbiased: pairwise MIS by default, or the generalised balance heuristic) and
// "restir-biased" (confidence-weighted 1/M resampling without MIS: biased where the neighbours'
// supports differ, e.g. at the volume's silhouette; its bias is measured by the tests).
#pragma once

#include "gpu/pipeline.h"
#include "gpu/shader_compiler.h"
#include "io/image.h"
#include "render/gpu_envmap.h"
#include "render/gpu_surfaces.h"
#include "render/gpu_volume.h"
#include "render/path_tracer.h"
#include "render/pixel_order.h"
#include "scene/scene.h"
#include "shaders/shared/reservoir.h"
#include "shaders/shared/restir_types.h"

#include <memory>
#include <string>
#include <vector>

namespace plume {

struct RestirOptions {
  int candidates = 4;        // M
  int candidatesMoving = 0;  // M while the camera moves (0: candidates)
  int neighbours = 2;        // k (as render.restir_neighbours)
  int radius = 16;           // px
  int rounds = 1;            // R (0: no spatial reuse)
  int roundsStatic = -1;     // R where camera and grid are both still (-1: rounds)
  int historyCap = 20;       // c (0: no temporal reuse)
  int historyCapMoving = 8;  // c while the camera moves (at most historyCap)
  int historyCapStatic = 0;  // c where camera and grid are both still (0: historyCap)
  uint32_t mis = shared::RS_MIS_PAIRWISE;
  int prefix = 16;           // K: vertices a reservoir's path holds (<= RS_MAX_VERTICES); the paths
                             // of more vertices are path traced in final shading (notes/restir.md)
  int lightCandidates = 2;   // L: light samples resampled at each candidate vertex (restir/bridge.glsl)
  int lightCandidatesMoving = 0;  // L while the camera moves (0: lightCandidates)
  bool reconnect = true;     // the reconnection shift at the first surface vertex after the primary
                             // (false: the copy shift; shared/restir_types.h)
  bool colourTarget = true;  // each pixel's target weighs the channels by its estimated colour
                             // (restir/colour.glsl; false: the luminance)
  bool emissionReservoir = true;  // with an emitting medium and lights, the paths that end in the
                                  // medium's emission in a reservoir of their own (restir/bridge.glsl
                                  // PLUME_RS_CLASSES; false: one reservoir for every path)
  // Tests only: the colour weights change every this many frames while the camera or the grid
  // moves (Restir::fillFrame); 1 makes every moving frame one whose history's domain keeps the
  // weights it had, which is what the Z-test must see often enough to resolve a mistake there.
  int colourMovingInterval = 4;
  // Tests only: the weights of each slot fixed and far apart ((5, 3, 2) / 10 and (2, 3, 5) / 10)
  // instead of estimated, so that a domain evaluated with the other slot's weights is a bias a
  // Z-test resolves (estimated weights change little from one change to the next).
  bool colourAlternate = false;
  // Tests only (no scene setting): when not (0, 0), every spatial round reuses exactly one
  // neighbour, the pixel at this offset, instead of k drawn in the disk. Unbiased (the choice does
  // not depend on the samples), but the offset is never mirrored, so an error of the shift that is
  // odd in its Jacobian does not cancel as it does between the disk's symmetric neighbours
  // (tests/test_restir_surfaces.cpp, the Jacobian test).
  int fixedNeighbourX = 0;
  int fixedNeighbourY = 0;
  // Tests only: false dispatches the general temporal pipeline even where the history's domain is
  // the current one, instead of the one compiled for that case (PLUME_RS_SAME_DOMAIN: identity
  // shift, stored targets); the two must give one image to rounding (tests/test_restir.cpp).
  bool sameDomainTemporal = true;
  // Tests only: false runs every pixel through the walking pipelines, instead of those whose
  // camera rays may meet the volume only (render/pixel_order.h) and walk-free variants of the
  // passes over the others (PLUME_RS_OUTSIDE); the two must give one image, bit for bit.
  bool cullOutside = true;
  // Tests only: false traces the lamp reservoir's camera rays in every pixel, instead of those
  // whose rays may meet an emitter's front (render/pixel_order.h emitterPixelMask; the others'
  // reservoirs are empty either way); the two must give one image, bit for bit.
  bool cullLampPixels = true;
  // Tests only: false draws the lamp reservoir's camera rays on the rectangle of each pixel where an
  // emitter's front may be seen (render/pixel_order.h emitterPixelRects), or without lampRects on
  // the whole pixel, instead of on the pieces of the pixel that the emitters' projections cover,
  // chosen by Le times their area (emitterPixelTriangles; restir/candidates.glsl
  // rs_lamp_triangle_candidates); same expectation, other images. Only with cullLampPixels.
  bool lampTriangles = true;
  bool lampRects = true;
  // Tests only: the words of the parameter buffer the pieces may take (0: as many as the device's
  // largest storage buffer leaves); pixels past it draw in their rectangles (lampRectPixels()).
  size_t lampPieceWords = 0;
  // Tests only: true keeps the stored paths' vertices in a storage buffer (PLUME_RS_VERTEX_BUFFER)
  // as on a device whose texel buffers cannot hold them but whose storage buffers can (otherwise
  // the device's limits choose: Restir::Restir); the two must give one image, bit for bit.
  bool verticesInStorageBuffer = false;
  std::string name() const;  // e.g. "restir pairwise M4 k3 r16 R1 c20" (r: radius in px)
};
// From the scene's render settings (render.restir_mis; mode restir-biased's RS_MIS_BIASED is set
// by its estimator, render/restir_estimator.cpp).
RestirOptions restirOptionsOf(const RenderSettings& rs);

class Restir {
 public:
  // kernelCounters: FeatureSet::kernelCounters (the kernel benchmark only).
  Restir(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const Scene& scene, const RestirOptions& options,
         bool kernelCounters = false);

  const RestirOptions& options() const { return options_; }
  // Reservoirs per pixel and set: 2 where an emitting medium's emission paths have their own
  // (RestirOptions::emissionReservoir, with lights), else 1.
  uint32_t classes() const { return classes_; }
  const FeatureSet& features() const { return features_; }
  // The volume of the frame about to be rendered and the previous frame's (temporal reuse
  // evaluates the history's target with it); pass the same volume twice for a still grid. Both
  // must stay alive until the next setVolumes.
  void setVolumes(const GpuVolumeResources& current, const GpuVolumeResources& previous);
  // Forgets the history (the next frame has no temporal reuse), e.g. to start an independent run.
  void resetHistory();
  // Renders `frame` (camera pose of that frame) with seed render.seed + 0x9E3779B9 * sequence:
  // independent sequences for the same frame are decorrelated. Returns the frame's image (one
  // ReSTIR sample per pixel; its variance channel is 0). `iteration` > 0 renders the same frame again
  // with fresh random numbers (the random streams are keyed by frame * 1024 + iteration, so
  // iteration < kMaxIterations).
  static constexpr uint32_t kMaxIterations = 1024;
  Image renderFrame(int frame, uint32_t sequence = 0, uint32_t iteration = 0);
  // The same without the read-back: the frame's final shading restarts the accumulation on the
  // device (accumulate = false) or is averaged into it (true); readImage gives the mean and the
  // variance of the mean of the accumulated frames, accumulation() the device buffer itself.
  void render(int frame, uint32_t sequence, uint32_t iteration, bool accumulate);
  Image readImage() const;
  const gpu::Buffer& accumulation() const { return output_; }
  const PassTimes& lastPassTimes() const { return passTimes_; }
  double lastFrameGpuMs() const;
  // Reservoir unpacks whose non-finite weights were dropped since the last call (DESIGN §4.2.3):
  // the passes count on the device; one read-back when asked, not one per iteration.
  uint32_t takeDroppedCount();
  // Pixels of the last frame whose lamp reservoir traced its camera rays (emitterPixelMask; every
  // pixel without options().cullLampPixels; 0 without emissive surfaces).
  uint32_t lampPixels() const { return lampPixels_; }
  // Of those, the pixels that drew their rays in their rectangles although the pieces were asked
  // for (RestirOptions::lampTriangles): their pieces would not fit the device's storage buffer
  // (the pixels with the most pieces go first; logged as a warning).
  uint32_t lampRectPixels() const { return lampRectPixels_; }

 private:
  void fillFrame(int frame, uint32_t sequence, uint32_t key);
  // Final shading's tail: records its dispatches from `first` on (at most kTailDispatchesPerSubmit,
  // the last one counting the walks still alive); the count read back and reset.
  static constexpr uint32_t kTailDispatchesPerSubmit = 4;
  uint32_t recordTail(VkCommandBuffer cmd, shared::RsPush push, uint32_t first);
  uint32_t tailAlive();
  void resetTailAlive();
  std::vector<gpu::ComputePass*> passes() const;

  gpu::Context& ctx_;
  const Scene& scene_;
  RestirOptions options_;
  FeatureSet features_;
  std::unique_ptr<GpuEnvironmentMap> envMap_;
  std::unique_ptr<GpuSurfaces> surfaces_;  // only for a scene with surfaces
  std::unique_ptr<gpu::ComputePass> candidates_, temporal_, temporalSame_, spatial_, shade_;
  std::unique_ptr<gpu::ComputePass> candidatesMoving_;  // with lightCandidatesMoving (null: candidates_ serves)
  std::unique_ptr<gpu::ComputePass> colour_;  // the targets' colour weights (passes/restir_colour.comp)
  // The colour weights (restir/colour.glsl): this frame's slot, whether this frame writes it, the
  // frames since they last changed and how many until they change again in a still view.
  uint32_t colourSet_ = 0;
  bool colourUpdate_ = false;
  bool colourWritten_ = false;  // the weights were written once (luminance: grey, once)
  uint32_t colourStep_ = 0;  // how this frame's walks enter their estimate (passes/restir_colour.comp)
  bool colourStill_ = false;  // the previous frame was a still one (its history in its domain)
  uint32_t colourAge_ = 0;
  uint32_t colourInterval_ = 1;
  bool moved_ = false;  // this frame's camera moved since the previous frame of the sequence (fillFrame)
  std::unique_ptr<gpu::ComputePass> lamps_;  // the lamps seen directly (only with emissive surfaces)
  std::unique_ptr<gpu::ComputePass> lampsRect_;  // with pieces, for the pixels whose pieces do not fit
  // The passes' variants for the pixels whose camera rays miss the volume (PLUME_RS_OUTSIDE;
  // null with surfaces, or without options_.cullOutside).
  std::unique_ptr<gpu::ComputePass> candidatesOut_, temporalOut_, spatialOut_, shadeOut_;
  std::unique_ptr<gpu::ComputePass> tail_;  // final shading's tail (null without one)
  uint32_t tailDispatches_ = 0;             // its dispatches per frame at most (max_bounces' walk)
  bool verticesInBuffer_ = false;           // the stored paths' vertices in a storage buffer (PLUME_RS_VERTEX_BUFFER)
  // Reservoir classes (restir/bridge.glsl PLUME_RS_CLASSES): 2 where an emitting medium's emission
  // paths have a reservoir of their own (class c of set s is set s + c * RS_SETS), else 1.
  uint32_t classes_ = 1;
  gpu::GpuTimer timer_;
  gpu::TexelBuffer lightBuffer_;
  gpu::Buffer frameBuffer_, lightChoice_, paramBuffer_, output_, counters_;
  // The reservoirs, the path heads with the passes' state, the paths' vertices 2..n
  // (restir/bindings.glsl)
  gpu::TexelBuffer reservoirs_, paths_, bounces_;
  gpu::Buffer bounceBuffer_;  // the vertices where a storage buffer holds them and texels cannot
  shared::GpuFrame frame_{};
  shared::RestirParams params_{};
  uint32_t history_ = 0;
  bool hasHistory_ = false;
  uint32_t prevSequence_ = 0;
  uint64_t currentSerial_ = 0, previousSerial_ = 0;  // volumes given to setVolumes
  uint64_t renderedSerial_ = 0;                      // the volume the history was rendered with
  shared::GpuCamera prevCam_{};
  glm::vec3 centre_{0.0f};  // world centre of the volume's bounds (reprojection depth)
  VolumeFootprint footprint_;  // where the current volume's density may be non-zero (pixelOrder_)
  // The frame's pixels, those that may see the volume first (render/pixel_order.h), and the
  // camera and volume they were found for (recomputed and uploaded when either changes).
  PixelOrder pixelOrder_;
  int rounds_ = 1;  // this frame's spatial rounds (options_.rounds, or roundsStatic where nothing changed)
  uint32_t lampPixels_ = 0;  // the lamp pass's list (after the order and the mask in paramBuffer_)
  uint32_t lampRectPixels_ = 0;  // its last ones, those of lampsRect_ (after the first ones' words)
  uint32_t lampRectListBegin_ = 0;  // where their list starts in rsPixels
  bool lampRectWarned_ = false;
  bool lampTriangles() const { return options_.lampTriangles && options_.cullLampPixels; }
  shared::GpuCamera orderCam_{};
  uint64_t orderSerial_ = 0;
  PassTimes passTimes_;
};

}  // namespace plume
