#include "render/restir.h"

#include "core/error.h"
#include "core/log.h"
#include "render/filter_probe.h"
#include "render/gpu_scene.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <numeric>

namespace plume {

std::string RestirOptions::name() const {
  const char* kind = mis == shared::RS_MIS_GBH ? "gbh" : mis == shared::RS_MIS_BIASED ? "biased" : "pairwise";
  // The prefix only when it is not the default, so the names of earlier benches still match.
  // The light candidates likewise.
  const std::string k = (prefix == RestirOptions{}.prefix ? "" : strf(" K%d", prefix)) +
                        (lightCandidates == RestirOptions{}.lightCandidates ? "" : strf(" L%d", lightCandidates)) +
                        (lightCandidatesMoving == RestirOptions{}.lightCandidatesMoving ? "" : strf(" Lm%d", lightCandidatesMoving)) +
                        (historyCapMoving == RestirOptions{}.historyCapMoving ? "" : strf(" cm%d", historyCapMoving)) +
                        (historyCapStatic == RestirOptions{}.historyCapStatic ? "" : strf(" cs%d", historyCapStatic)) +
                        (candidatesMoving == RestirOptions{}.candidatesMoving ? "" : strf(" Mm%d", candidatesMoving)) +
                        (roundsStatic == RestirOptions{}.roundsStatic ? "" : strf(" Rs%d", roundsStatic)) +
                        (reconnect ? "" : " copy") + (colourTarget ? "" : " lum") + (emissionReservoir ? "" : " one") +
                        (fixedNeighbourX || fixedNeighbourY ? strf(" at(%d,%d)", fixedNeighbourX, fixedNeighbourY) : "");
  if (rounds == 0 && roundsStatic <= 0) return strf("restir %s M%d R0 c%d%s", kind, candidates, historyCap, k.c_str());
  return strf("restir %s M%d k%d r%d R%d c%d%s", kind, candidates, neighbours, radius, rounds, historyCap, k.c_str());
}

RestirOptions restirOptionsOf(const RenderSettings& rs) {
  RestirOptions o;
  o.candidates = rs.restirCandidates;
  o.candidatesMoving = rs.restirCandidatesMoving;
  o.neighbours = rs.restirNeighbours;
  o.radius = rs.restirRadius;
  o.rounds = rs.restirRounds;
  o.roundsStatic = rs.restirRoundsStatic;
  o.historyCap = rs.restirHistoryCap;
  o.historyCapMoving = rs.restirHistoryCapMoving;
  o.historyCapStatic = rs.restirHistoryCapStatic;
  o.mis = rs.restirMis == "gbh" ? shared::RS_MIS_GBH : shared::RS_MIS_PAIRWISE;
  o.prefix = rs.restirPrefix;
  o.lightCandidates = rs.restirLightCandidates;
  o.lightCandidatesMoving = rs.restirLightCandidatesMoving;
  o.reconnect = rs.restirShift != "copy";
  o.colourTarget = rs.restirTarget != "luminance";
  o.emissionReservoir = rs.restirEmissionReservoir != "shared";
  return o;
}

namespace {

// Each light's probability of being chosen for a candidate's light sample and the running sum
// (shared::GpuLightChoice): 90% in proportion to an estimate of the light's
// contribution to a scattering point at the volume's centre (phase-averaged: a sun's irradiance
// or a point light's intensity / r^2 over 4 pi, an environment's radiance), 10% uniform, so no
// light with a nonzero estimate is starved. A uniform choice spent half the candidates of the
// bundled smoke on its dim sky; one candidate per light at every vertex cost more than it gave
// (bundled smoke at 128², r2: 4.85x -> 5.26x static, 3.79x -> 3.70x moving with one light by
// power; Blender smoke: 3.53x -> 5.19x and 2.72x -> 3.48x: the sky's light rays through dense
// smoke carry almost nothing).
// envMapMean: an environment map's mean radiance over the sphere (GpuEnvironmentMap). With
// emissive surfaces one more entry, after the scene's lights, stands for a point on them
// (restir/bridge.glsl rs_sample_light), its estimate GpuSurfaces::emitterPowerAt(centre).
std::vector<shared::GpuLightChoice> lightChoice(const Scene& scene, glm::vec3 centre, glm::vec3 envMapMean,
                                                const GpuSurfaces* surfaces) {
  const bool emitters = surfaces && surfaces->emitterCount() > 0;
  const size_t n = scene.lights.size() + (emitters ? 1 : 0);
  std::vector<shared::GpuLightChoice> choice(std::max<size_t>(n, 1), shared::GpuLightChoice{});
  if (n == 0) return choice;
  auto lum = [](glm::vec3 c) { return std::max(0.0, (double(c.x) + c.y + c.z) / 3.0); };
  std::vector<double> power(n, 0.0);
  double total = 0.0;
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& l = scene.lights[i];
    switch (l.type) {
      case LightType::Sun: power[i] = lum(l.irradiance) / (4.0 * M_PI); break;
      case LightType::Point: {
        const double r2 = std::max(1e-12, double(glm::dot(l.position - centre, l.position - centre)));
        power[i] = lum(l.intensity) / (4.0 * M_PI * r2);
        break;
      }
      case LightType::Environment: power[i] = l.map.empty() ? lum(l.radiance * l.scale) : lum(envMapMean); break;
    }
    total += power[i];
  }
  if (emitters) {
    power[n - 1] = surfaces->emitterPowerAt(centre);
    total += power[n - 1];
  }
  double cdf = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const double p = total > 0.0 ? 0.9 * power[i] / total + 0.1 / double(n) : 1.0 / double(n);
    cdf += p;
    choice[i].probability = float(p);
    choice[i].cdf = i + 1 == n ? 2.0f : float(cdf);  // the last light catches rounding
  }
  return choice;
}

constexpr uint32_t kSets = shared::RS_SETS;
constexpr size_t kLampPieceWords = 8;  // a piece of an emitter's projection (restir/bindings.glsl rs_lamp_piece)

}  // namespace

Restir::Restir(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const Scene& scene, const RestirOptions& options,
               bool kernelCounters)
    : ctx_(ctx), scene_(scene), options_(options), features_(featuresOf(scene)), timer_(ctx, 32) {
  features_.kernelCounters = kernelCounters;
  features_.hardwareFilter = useHardwareFilter(ctx, compiler, scene.render.densityFilter);  // render/filter_probe.h
  envMap_ = std::make_unique<GpuEnvironmentMap>(ctx, scene);  // bad maps fail before compiling
  if (features_.surfaces) {
    surfaces_ = std::make_unique<GpuSurfaces>(ctx, scene);
    features_.bvhStack = surfaces_->bvhStats().depth;
  }
  if (options_.prefix < 1 || options_.prefix > int(shared::RS_MAX_VERTICES)) {
    throw InputError(scene.path + strf(": render.restir_prefix: expected 1 to %u (got %d)", shared::RS_MAX_VERTICES,
                                       options_.prefix));
  }
  // Reservoirs hold paths of at most `prefix` vertices; a longer max_bounces adds the tail, a
  // path-traced estimate of the paths with more vertices, to final shading (restir/shade.glsl).
  // In an emitting medium, or with emissive surfaces (hit by a sampled direction), a reservoir's
  // path may end with one more vertex that only emits (rs_emission_vertices: min(max_bounces,
  // prefix) + 1, at most RS_MAX_VERTICES), and the tail also gathers the emission of longer paths.
  const bool endsInEmission = features_.emission || features_.emitters;
  const int prefix = std::min(options_.prefix, std::max(1, scene.render.maxBounces));
  const int emitting = std::min({scene.render.maxBounces + 1, prefix + 1, int(shared::RS_MAX_VERTICES)});
  const bool tail = scene.render.maxBounces > prefix || (endsInEmission && scene.render.maxBounces + 1 > emitting);
  const int vertices = endsInEmission ? emitting : prefix;  // stored per path
  // The paths that end in an emitting medium's emission in a reservoir of their own, beside those
  // that end at a light (restir/bridge.glsl PLUME_RS_CLASSES), where both kinds exist: a pixel
  // shades one path per reservoir, and one reservoir for both made its colour the colour of
  // whichever end won (on the bundled fire half the error per frame: notes/restir.md "Session 40").
  const bool lightPaths = !scene.lights.empty() || features_.emitters;
  classes_ = options_.emissionReservoir && features_.emission && lightPaths ? 2u : 1u;
  const size_t sets = size_t(kSets) * classes_;
  // Every per-pixel buffer below within the device's limits, checked before anything is compiled.
  // All but the accumulation (which the viewer's display reads) are storage texel buffers, whose
  // limit on lavapipe is 2^27 texels (2 GiB) where a storage buffer's is 128 MiB: at 1920x1080 the
  // storage buffers held none of the four largest (session 25).
  // The vertices, the one array that grows with the bounces, go in a storage buffer instead where
  // the texel buffers cannot hold them and a storage buffer can (desktop GPU drivers publish 2^27
  // texels, as lavapipe, and 2-4 GiB storage buffers: 3840x2160 at 8 bounces needs 174 M texels).
  const size_t stateTexels =
      shared::RS_STATE_SLOTS + shared::RS_COLOUR_SLOTS + (features_.emitters ? shared::RS_LAMP_SLOTS : 0);
  const size_t pixels = size_t(scene.camera.width) * size_t(scene.camera.height);
  const uint32_t stride = uint32_t(std::max(1, vertices - 1));  // vertex slots per pixel and set
  const size_t vertexTexels = sets * stride;                      // per pixel
  {
    const VkPhysicalDeviceLimits& lim = ctx.limits();
    const bool texelsFit = pixels * vertexTexels <= lim.maxTexelBufferElements;
    const bool bufferFits = pixels * vertexTexels * sizeof(glm::vec4) <= lim.maxStorageBufferRange;
    // Where neither holds them, the larger kind names the limit in the message below.
    const bool bufferLarger = uint64_t(lim.maxStorageBufferRange) > uint64_t(lim.maxTexelBufferElements) * sizeof(glm::vec4);
    verticesInBuffer_ = options_.verticesInStorageBuffer || (!texelsFit && (bufferFits || bufferLarger));
    gpu::PerPixelBuffers perPixel;
    perPixel.storageBytes = {{"accumulation", 2 * sizeof(glm::vec4)}, {"pixel order", sizeof(uint32_t)}};
    perPixel.texels = {{"reservoir paths and pass state", sets * 2 + stateTexels}, {"reservoirs", sets}};
    if (verticesInBuffer_) {
      perPixel.storageBytes.push_back({"reservoir path vertices", vertexTexels * sizeof(glm::vec4)});
    } else {
      perPixel.texels.push_back({"reservoir path vertices", vertexTexels});
    }
    gpu::requirePerPixelStorage(ctx, "ReSTIR", perPixel, scene.camera.width, scene.camera.height,
                                "--mode pt renders large images in parts; or a device with larger limits (--device)");
  }
  if (options_.neighbours > int(shared::RS_MAX_NEIGHBOURS)) {
    throw InputError(scene.path + strf(": render.restir_neighbours: at most %u", shared::RS_MAX_NEIGHBOURS));
  }
  if (options_.lightCandidates < 1 || options_.lightCandidates > 64) {
    throw InputError(scene.path + strf(": render.restir_light_candidates: expected 1 to 64 (got %d)", options_.lightCandidates));
  }
  if (options_.lightCandidatesMoving < 0 || options_.lightCandidatesMoving > 64) {
    throw InputError(scene.path + strf(": render.restir_light_candidates_moving: expected 0 to 64 (got %d)",
                                       options_.lightCandidatesMoving));
  }
  // Light resampling (restir/bridge.glsl rs_resample_light) only where it was measured to help:
  // among emissive triangles. With a sun and a sky behind dense, strongly forward-scattering smoke
  // the unshadowed term prefers the sun, whose rays the smoke blocks, and L = 2 made the sky's
  // samples rare and heavy-tailed (ExtremeSuite.StronglyForwardScatteringBacklit failed: worst
  // pixel z -5.3); one sun, one point light or a constant sky alone have nothing to choose.
  const int lightCandidates = features_.emitters ? options_.lightCandidates : 1;
  using gpu::BindingType;
  // shaders/restir/bindings.glsl (numbers in shaders/shared/bindings.h)
  // Every binding in a table must be written before a dispatch (lavapipe reads them all): the
  // emission's exist only in the tables of an emitting scene, the surfaces' (past the emission's)
  // only in those of a scene with surfaces.
  const uint32_t count = features_.surfaces ? shared::RS_SURFACE_BINDING_COUNT
                         : features_.emission ? shared::EMISSION_BINDING_COUNT
                                              : shared::RS_BINDING_COUNT;
  const gpu::BindingTypes types =
      sceneBindingTypes(true, features_.emission, features_.surfaces, shared::RS_SURF_BINDING_SHIFT);
  gpu::BindingTypes withTexels = types;
  withTexels.push_back({shared::BIND_RS_RESERVOIRS, BindingType::StorageTexelBuffer});
  withTexels.push_back({shared::BIND_RS_PATHS, BindingType::StorageTexelBuffer});
  if (!verticesInBuffer_) withTexels.push_back({shared::BIND_RS_BOUNCES, BindingType::StorageTexelBuffer});
  const std::vector<BindingType> bindings = gpu::bindingTable(count, withTexels);
  const gpu::ShaderDefines defines = features_.defines();
  const std::string variant = " [" + features_.name() + "]";
  // Each pass is compiled with only the code its options use (MIS kind, temporal or spatial,
  // light types): on a SIMD back end such as lavapipe the straight-line code of branches not
  // taken still runs under a mask (measured: -20 to -40% per reuse pass).
  auto make = [&](const char* file, const char* name, gpu::ShaderDefines extra, int light = 0) {
    gpu::ShaderDefines d = defines;
    // Final shading's unbiased transmittances of light rays, escaping camera rays and the tail's
    // light rays: residual ratio tracking against the mean field (volume/walk.glsl) at 16x the
    // residual majorant: on the bundled smoke (64², temporal reuse, when every path segment took
    // it too) relMSE 0.011 at 1x, 0.0082 at 2x, 0.0054 at 8x, 0.0046 at 16x, 0.0046 at 32x,
    // shading 3.4 -> 5.9 ms; 16x is where the error stops falling (notes/restir.md). The path's
    // segments take vol_residual_ratio at PLUME_RS_RATIO_SCALE brick majorants (session 27).
    d.emplace_back("PLUME_RS_RESIDUAL_SCALE", "16.0f");
    d.emplace_back("PLUME_RS_MIS", std::to_string(options_.mis) + "u");
    d.emplace_back("PLUME_RS_LIGHT_CANDIDATES", std::to_string(light > 0 ? light : lightCandidates));
    d.emplace_back("PLUME_RS_CLASSES", std::to_string(classes_));
    // The reconnection shift only where there are surface vertices to reconnect to.
    if (features_.surfaces && options_.reconnect) d.emplace_back("PLUME_RS_RECONNECT", "1");
    if (verticesInBuffer_) d.emplace_back("PLUME_RS_VERTEX_BUFFER", "1");
    d.insert(d.end(), extra.begin(), extra.end());
    return std::make_unique<gpu::ComputePass>(ctx, compiler.compile(file, d), bindings,
                                              uint32_t(sizeof(shared::RsPush)), name + variant, glm::uvec3(64, 1, 1));
  };
  candidates_ = make("passes/restir_candidates.comp", "restir candidates", {});
  colour_ = make("passes/restir_colour.comp", "restir colour",
                 {{"PLUME_RS_COLOUR_TARGET", options_.colourTarget ? "1" : "0"},
                  {"PLUME_RS_COLOUR_ALTERNATE", options_.colourAlternate ? "1" : "0"}});
  // Frames whose camera moved may resample another number of light samples a vertex: a per-frame
  // constant of the canonical reservoir's candidates, as their M is (fillFrame), so reuse stays
  // unbiased. A pipeline of its own (L is compiled in), with emissive surfaces only.
  const int lightMoving = features_.emitters ? options_.lightCandidatesMoving : 0;
  if (lightMoving > 0 && lightMoving != lightCandidates) {
    candidatesMoving_ = make("passes/restir_candidates.comp", "restir candidates (moving)", {}, lightMoving);
  }
  // The lamps seen directly, over the pixels whose camera rays may meet an emitter (restir/candidates.glsl).
  if (features_.emitters) {
    gpu::ShaderDefines lampDefines;
    if (lampTriangles()) lampDefines.emplace_back("PLUME_RS_LAMP_TRIANGLES", "1");
    lamps_ = make("passes/restir_lamps.comp", "restir lamps", lampDefines);
    if (lampTriangles()) lampsRect_ = make("passes/restir_lamps.comp", "restir lamps in rectangles", {});
  }
  temporal_ = make("passes/restir_reuse.comp", "restir temporal", {{"PLUME_RS_TEMPORAL", "1"}});
  // Temporal reuse where the history's domain is the current one (params_.historySameDomain):
  // the identity shift and stored targets only, no target evaluation compiled in (restir/reuse.glsl).
  temporalSame_ = make("passes/restir_reuse.comp", "restir temporal (same domain)",
                       {{"PLUME_RS_TEMPORAL", "1"}, {"PLUME_RS_SAME_DOMAIN", "1"}});
  spatial_ = make("passes/restir_reuse.comp", "restir spatial", {{"PLUME_RS_TEMPORAL", "0"}});
  shade_ = make("passes/restir_shade.comp", "restir shade",
                tail ? gpu::ShaderDefines{{"PLUME_RS_TAIL", "1"}} : gpu::ShaderDefines{});
  // The pixels whose camera rays miss the volume go through variants without walks (their
  // reservoirs stay empty and their targets are 0; render/pixel_order.h): on lavapipe a walk's
  // code costs a subgroup its masked pass even where no lane walks (the bundled smoke: ~60% of
  // the pixels, ~35% of an iteration; notes/restir.md "Session 24"). Not with surfaces, which a
  // camera ray may meet anywhere.
  if (!features_.surfaces && options_.cullOutside) {
    const gpu::ShaderDefines out = {{"PLUME_RS_OUTSIDE", "1"}};
    candidatesOut_ = make("passes/restir_candidates.comp", "restir candidates (outside)", out);
    temporalOut_ = make("passes/restir_reuse.comp", "restir temporal (outside)", {{"PLUME_RS_TEMPORAL", "1"}, out[0]});
    spatialOut_ = make("passes/restir_reuse.comp", "restir spatial (outside)", {{"PLUME_RS_TEMPORAL", "0"}, out[0]});
    shadeOut_ = make("passes/restir_shade.comp", "restir shade (outside)",
                     tail ? gpu::ShaderDefines{{"PLUME_RS_TAIL", "1"}, out[0]} : out);
  }
  // The tail's walk goes on in dispatches of at most RS_TAIL_SEGMENTS segments each (lavapipe's
  // loop budget, docs/architecture.md): enough of them for the longest walk, max_bounces
  // segments (one more in an emitting medium).
  if (tail) {
    tail_ = make("passes/restir_tail.comp", "restir tail", {});
    const uint32_t segments = uint32_t(scene.render.maxBounces) + (endsInEmission ? 1u : 0u);
    tailDispatches_ = (segments + shared::RS_TAIL_SEGMENTS - 1) / shared::RS_TAIL_SEGMENTS;
  }

  const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  frameBuffer_ = gpu::Buffer(ctx, sizeof(shared::GpuFrame), storage, "frame parameters");
  const std::vector<shared::GpuLight> lights = gpuLights(scene);
  lightBuffer_ = lightTexels(ctx, lights);
  const size_t choices = std::max(lights.size(), scene.lights.size() + (features_.emitters ? 1 : 0));
  lightChoice_ = gpu::Buffer(ctx, choices * sizeof(shared::GpuLightChoice), storage, "light choice");
  // The parameters, then the frame's pixels in the passes' order, then with emissive surfaces a
  // bit per pixel, set where its camera rays may meet an emitter, those pixels' list and their
  // rectangles, two words each (restir/bindings.glsl rsPixels, rs_lamp_pixel, rs_lamp_rect).
  const size_t lampWords = features_.emitters ? (pixels + 31) / 32 + 3 * pixels : 0;
  paramBuffer_ = gpu::Buffer(ctx, sizeof(shared::RestirParams) + (pixels + lampWords) * sizeof(uint32_t), storage,
                             "restir parameters");
  static_assert(sizeof(shared::RsPacked) == 16 && sizeof(shared::RsPathHead) == 32);  // 1 and 2 texels
  reservoirs_ = gpu::TexelBuffer(ctx, nullptr, sets * pixels, VK_FORMAT_R32G32B32A32_UINT, "reservoirs", true);
  // The path heads, then each pixel's state between the dispatches of a pass (the candidates'
  // running reservoir, the tail's walk: restir/bridge.glsl rs_state_slot), then with emissive
  // surfaces the lamp reservoirs (rs_lamp_slot).
  paths_ = gpu::TexelBuffer(ctx, nullptr, (sets * 2 + stateTexels) * pixels, VK_FORMAT_R32G32B32A32_UINT,
                            "reservoir paths and pass state", true);
  if (verticesInBuffer_) {
    bounceBuffer_ = gpu::Buffer(ctx, sets * pixels * stride * sizeof(glm::vec4), storage, "reservoir path vertices");
  } else {
    bounces_ = gpu::TexelBuffer(ctx, nullptr, sets * pixels * stride, VK_FORMAT_R32G32B32A32_UINT,
                                "reservoir path vertices", true);
  }
  output_ = gpu::Buffer(ctx, 2 * pixels * sizeof(glm::vec4), storage, "restir accumulation");
  counters_ = gpu::Buffer(ctx, shared::RS_COUNTERS * sizeof(uint32_t), storage, "restir counters");
  counters_.fillZero();
  output_.fillZero();
  reservoirs_.fillZero();
  paths_.fillZero();
  for (gpu::ComputePass* p : passes()) {
    p->set.bind(shared::BIND_FRAME, frameBuffer_);
    p->set.bind(shared::BIND_LIGHTS, lightBuffer_);
    p->set.bind(shared::BIND_LIGHT_CHOICE, lightChoice_);
    envMap_->bind(p->set);
    if (surfaces_) surfaces_->bind(p->set, shared::RS_SURF_BINDING_SHIFT);
    p->set.bind(shared::BIND_RS_PARAMS, paramBuffer_);
    p->set.bind(shared::BIND_RS_RESERVOIRS, reservoirs_);
    p->set.bind(shared::BIND_RS_PATHS, paths_);
    if (verticesInBuffer_) {
      p->set.bind(shared::BIND_RS_BOUNCES, bounceBuffer_);
    } else {
      p->set.bind(shared::BIND_RS_BOUNCES, bounces_);
    }
    p->set.bind(shared::BIND_RS_OUTPUT, output_);
    p->set.bind(shared::BIND_RS_COUNTERS, counters_);
  }
  params_.candidates = uint32_t(options_.candidates);
  params_.bounceStride = stride;
  params_.prefixVertices = uint32_t(prefix);
  params_.walksPerDispatch = std::max(1u, shared::RS_CANDIDATE_VERTICES / uint32_t(endsInEmission ? emitting : prefix));
  params_.pixelCount = uint32_t(pixels);
  // The scene's lights and, with emissive surfaces, one entry for a point on them.
  params_.lightCount = uint32_t(scene.lights.size()) + (surfaces_ && surfaces_->emitterCount() > 0 ? 1u : 0u);
  params_.reprojectionDepth = 1.0f;
  const bool fixedNeighbour = options_.fixedNeighbourX != 0 || options_.fixedNeighbourY != 0;
  params_.neighbours = fixedNeighbour ? 1u : uint32_t(options_.neighbours);
  params_.radius = float(options_.radius);
  params_.fixedNeighbourX = options_.fixedNeighbourX;
  params_.fixedNeighbourY = options_.fixedNeighbourY;
}

void Restir::setVolumes(const GpuVolumeResources& current, const GpuVolumeResources& previous) {
  PLUME_CHECK(current.hasMeanField() && previous.hasMeanField());  // baked with BakeOptions::meanField
  if (features_.hardwareFilter) current.requireLinearFilter();
  for (gpu::ComputePass* p : passes()) {
    current.bind(p->set);
    current.bindMeanField(p->set);
    previous.bindAsPrevious(p->set);
  }
  // Reprojection depth: the distance from the camera to the volume's centre (a per-frame
  // constant, so the history pixel never depends on a sample).
  const shared::GpuVolume& v = current.params();
  footprint_ = current.footprint();
  const glm::vec3 centre = glm::vec3(v.indexToWorld * glm::vec4(0.5f * (v.boundsMin + v.boundsMax), 1.0f));
  centre_ = centre;
  currentSerial_ = current.serial();
  previousSerial_ = previous.serial();
  const std::vector<shared::GpuLightChoice> choice = lightChoice(scene_, centre, envMap_->meanRadiance(), surfaces_.get());
  lightChoice_.upload(choice.data(), choice.size() * sizeof(shared::GpuLightChoice));
}

std::vector<gpu::ComputePass*> Restir::passes() const {
  std::vector<gpu::ComputePass*> p = {candidates_.get(), temporal_.get(), temporalSame_.get(), spatial_.get(),
                                      shade_.get(), colour_.get()};
  for (gpu::ComputePass* q : {candidatesMoving_.get(), candidatesOut_.get(), temporalOut_.get(), spatialOut_.get(),
                              shadeOut_.get(), tail_.get(), lamps_.get(), lampsRect_.get()}) {
    if (q) p.push_back(q);
  }
  return p;
}

void Restir::resetHistory() { hasHistory_ = false; }

void Restir::fillFrame(int frame, uint32_t sequence, uint32_t key) {
  frame_ = gpuFrame(scene_, frame, uint32_t(scene_.render.seed) + 0x9E3779B9u * sequence, key);
  const shared::GpuCamera& cam = frame_.camera;
  const bool still = sameCamera(prevCam_, cam);
  // The history's domain is the current one (a still camera over the grid it was rendered with):
  // the temporal shift is the identity and both cross-domain targets are the stored ones.
  const bool sameVolume = previousSerial_ == currentSerial_ && renderedSerial_ == currentSerial_;
  // The cap depends on the cameras and grids only, never on a sample, so any value keeps reuse
  // unbiased. Where nothing changed (the same domain) the static cap, if set and temporal reuse is on.
  int cap = options_.historyCap;
  if (!still) {
    cap = std::min(cap, options_.historyCapMoving);
  } else if (sameVolume && cap > 0 && options_.historyCapStatic > 0) {
    cap = options_.historyCapStatic;
  }
  params_.historyCap = float(cap);
  // Likewise the candidates (a per-frame M is a constant of the canonical reservoir), in frames
  // whose camera moved since the previous frame of the sequence (the first frame keeps M).
  const bool moved = hasHistory_ && prevSequence_ == sequence && !still;
  params_.candidates = uint32_t(moved && options_.candidatesMoving > 0 ? options_.candidatesMoving : options_.candidates);
  moved_ = moved;  // and their light samples a vertex (candidatesMoving_)
  // And the spatial rounds where nothing changed (a per-frame constant too: which neighbours a
  // pixel reuses never depends on a sample).
  rounds_ = still && sameVolume && options_.roundsStatic >= 0 ? options_.roundsStatic : options_.rounds;
  const bool history = hasHistory_ && cap > 0 && prevSequence_ == sequence;
  if (history) params_.prevCamera = prevCam_;
  params_.historyValid = history ? 1u : 0u;
  params_.historySameDomain = history && still && sameVolume ? 1u : 0u;
  // The targets' colour weights (restir/colour.glsl) change only in frames where the history's
  // domain is evaluated with its own weights: without a history (every frame with
  // restir_history_cap 0), every 4th frame (options_.colourMovingInterval) while the camera or the grid
  // changes (the general temporal pipeline runs anyway; weights a few frames old serve as well as
  // any), and in a still view after 1, 2, 4, ... 64 frames, then every 64 (the general pipeline
  // once then, instead of the same-domain one, whose stored targets would be another function than
  // the current one). Each change walks every pixel once for the estimate they come from (about
  // one path-tracer sample: restir/colour.glsl).
  const bool sameDomain = params_.historySameDomain != 0u;
  ++colourAge_;
  if (!history) {
    colourUpdate_ = true;
  } else if (sameDomain) {
    if (!colourStill_) colourInterval_ = 1;  // the first still frame: 1, 2, 4, ... from here
    colourUpdate_ = colourAge_ >= colourInterval_;
  } else {
    colourUpdate_ = colourAge_ >= uint32_t(std::max(1, options_.colourMovingInterval));
  }
  colourStill_ = history && sameDomain;
  if (!options_.colourTarget) colourUpdate_ = !colourWritten_;  // grey, once
  // Their estimate: a frame without a history starts it over (it depends on nothing before it,
  // docs/farm.md); a still view averages every walk since it stood still, a moving one the last few.
  colourStep_ = !history ? 0u : sameDomain ? 1u : 3u;
  params_.colourHistorySet = colourSet_;
  if (colourUpdate_ && options_.colourTarget) {
    colourSet_ ^= 1u;
    if (sameDomain) colourInterval_ = std::min(2u * colourInterval_, 64u);
    colourAge_ = 0;
    params_.historySameDomain = 0u;
  }
  params_.colourSet = colourSet_;
  // The lamps seen directly (restir/candidates.glsl rs_lamp_reservoir): the sets alternate; the
  // history is the same pixel's only with a still camera.
  params_.lampSet ^= 1u;
  params_.lampHistory = history && still ? 1u : 0u;
  params_.lampSameVolume = sameVolume ? 1u : 0u;
  renderedSerial_ = currentSerial_;
  params_.reprojectionDepth = glm::length(centre_ - cam.position);
  frameBuffer_.upload(&frame_, sizeof(frame_));
  paramBuffer_.upload(&params_, sizeof(params_));
  // The pixels in the passes' order: those whose rays may meet the volume first, where the
  // outside variants exist (otherwise all of them count as inside).
  if (pixelOrder_.pixels.empty() || !sameCamera(orderCam_, cam) || orderSerial_ != currentSerial_) {
    const int w = scene_.camera.width, h = scene_.camera.height;
    pixelOrder_ = candidatesOut_ ? volumePixelOrder(cam, w, h, footprint_) : allPixels(w, h);
    std::vector<uint32_t> lamps;
    if (lamps_) {
      // The mask, then its pixels in the passes' order (the lamp pass's list; with surfaces every
      // pixel is inside, so that is tile order), then two words for each of them: its rectangle,
      // or with RestirOptions::lampTriangles the start and length of its list of pieces of emitter
      // projections (render/pixel_order.h emitterPixelTriangles), which follow, kLampPieceWords
      // words each (restir/bindings.glsl rs_lamp_piece). Where the pieces would not fit the
      // device's largest storage buffer, the pixels with the most pieces draw in their rectangles
      // instead, a list of their own after the others' words (lampsRect_), counted and logged.
      const size_t n = size_t(w) * size_t(h);
      const bool triangles = lampTriangles();
      std::vector<uint64_t> rects = options_.cullLampPixels ? emitterPixelRects(cam, w, h, surfaces_->emitterVertices())
                                                            : std::vector<uint64_t>(n, kWholePixelRect);
      const EmitterPixelLists lists =
          triangles ? emitterPixelTriangles(cam, w, h, surfaces_->emitterVertices()) : EmitterPixelLists{};
      lamps = emitterPixelMask(rects);
      std::vector<size_t> listed;
      for (uint32_t packed : pixelOrder_.pixels) {
        const size_t i = size_t(packed >> 16) * size_t(w) + (packed & 0xffffu);
        if (!((lamps[i / 32] >> (i % 32)) & 1u)) continue;
        // (a pixel that the rectangles mark but no piece reaches sees no emitter: out of the mask)
        if (triangles && lists.begin[i + 1] == lists.begin[i]) {
          lamps[i / 32] &= ~(1u << (i % 32));
          continue;
        }
        listed.push_back(i);
      }
      lampPixels_ = uint32_t(listed.size());
      std::vector<bool> inRect(listed.size(), !triangles);
      if (triangles) {
        const size_t device = (ctx_.limits().maxStorageBufferRange - sizeof(shared::RestirParams)) / sizeof(uint32_t);
        const size_t used = pixelOrder_.pixels.size() + lamps.size() + 3 * listed.size();
        const size_t limit = options_.lampPieceWords > 0 ? options_.lampPieceWords : device > used ? device - used : 0;
        size_t words = 0;
        for (size_t l = 0; l < listed.size(); ++l) words += kLampPieceWords * (lists.begin[listed[l] + 1] - lists.begin[listed[l]]);
        std::vector<size_t> byPieces;  // (only where they do not all fit)
        if (words > limit) {
          byPieces.resize(listed.size());
          std::iota(byPieces.begin(), byPieces.end(), size_t(0));
          std::stable_sort(byPieces.begin(), byPieces.end(), [&](size_t a, size_t b) {
            return lists.begin[listed[a] + 1] - lists.begin[listed[a]] > lists.begin[listed[b] + 1] - lists.begin[listed[b]];
          });
        }
        for (size_t l : byPieces) {
          if (words <= limit) break;
          inRect[l] = true;
          words -= kLampPieceWords * (lists.begin[listed[l] + 1] - lists.begin[listed[l]]);
        }
      }
      lampRectPixels_ = triangles ? uint32_t(std::count(inRect.begin(), inRect.end(), true)) : 0u;
      if (lampRectPixels_ > 0 && !lampRectWarned_) {
        logWarn(strf("restir: %u of %u pixels that may see an emitter draw their lamp rays in rectangles, not on the "
                     "emitters' pieces: the pieces would pass the device's largest storage buffer (%.0f MiB)",
                     lampRectPixels_, lampPixels_, ctx_.limits().maxStorageBufferRange / 1048576.0));
        lampRectWarned_ = true;
      }
      // The two lists, each followed by its pixels' words, then the pieces.
      const size_t first = pixelOrder_.pixels.size() + lamps.size() + 3 * listed.size();  // (in rsPixels)
      size_t next = first;
      for (const bool rect : {false, true}) {
        if (triangles && rect) lampRectListBegin_ = uint32_t(pixelOrder_.pixels.size() + lamps.size());
        for (size_t l = 0; l < listed.size(); ++l) {
          if (inRect[l] != rect) continue;
          const size_t i = listed[l];
          lamps.push_back(packPixel(uint32_t(i % size_t(w)), uint32_t(i / size_t(w))));
        }
        for (size_t l = 0; l < listed.size(); ++l) {
          if (inRect[l] != rect) continue;
          const size_t i = listed[l];
          if (!rect) {
            const uint32_t count = lists.begin[i + 1] - lists.begin[i];
            lamps.insert(lamps.end(), {uint32_t(next), count});
            next += kLampPieceWords * size_t(count);
          } else {
            const uint64_t r = options_.lampRects ? rects[i] : kWholePixelRect;
            lamps.insert(lamps.end(), {uint32_t(r), uint32_t(r >> 32)});
          }
        }
      }
      PLUME_CHECK(pixelOrder_.pixels.size() + lamps.size() == first);
      for (size_t l = 0; l < listed.size(); ++l) {
        if (inRect[l]) continue;
        for (uint32_t j = lists.begin[listed[l]]; j < lists.begin[listed[l] + 1]; ++j) {
          // The triangle's device index, its weight Le's luminance x the piece's area, the corners.
          const EmitterPiece& e = lists.pieces[j];
          const float weight = surfaces_->emitterLuminance()[e.triangle] * e.area;
          for (uint32_t word : {surfaces_->emitterTriangles()[e.triangle], std::bit_cast<uint32_t>(weight),
                                std::bit_cast<uint32_t>(e.a.x), std::bit_cast<uint32_t>(e.a.y), std::bit_cast<uint32_t>(e.b.x),
                                std::bit_cast<uint32_t>(e.b.y), std::bit_cast<uint32_t>(e.c.x), std::bit_cast<uint32_t>(e.c.y)}) {
            lamps.push_back(word);
          }
        }
      }
      PLUME_CHECK(pixelOrder_.pixels.size() + lamps.size() == next);
    }
    // The buffer grows where this frame's lists need more room (and is bound again).
    const size_t bytes = sizeof(shared::RestirParams) + (pixelOrder_.pixels.size() + lamps.size()) * sizeof(uint32_t);
    if (bytes > paramBuffer_.size()) {
      // (room to grow by half, within the device's range, which the pieces' budget above keeps bytes in)
      const size_t capacity = std::max<size_t>(bytes, std::min<size_t>(bytes + bytes / 2, ctx_.limits().maxStorageBufferRange));
      paramBuffer_ = gpu::Buffer(ctx_, capacity, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "restir parameters");
      for (gpu::ComputePass* p : passes()) p->set.bind(shared::BIND_RS_PARAMS, paramBuffer_);
      paramBuffer_.upload(&params_, sizeof(params_));
    }
    paramBuffer_.upload(pixelOrder_.pixels.data(), pixelOrder_.pixels.size() * sizeof(uint32_t),
                        sizeof(shared::RestirParams));
    if (!lamps.empty()) {
      paramBuffer_.upload(lamps.data(), lamps.size() * sizeof(uint32_t),
                          sizeof(shared::RestirParams) + pixelOrder_.pixels.size() * sizeof(uint32_t));
    }
    orderCam_ = cam;
    orderSerial_ = currentSerial_;
  }
  prevCam_ = cam;
}

Image Restir::renderFrame(int frame, uint32_t sequence, uint32_t iteration) {
  render(frame, sequence, iteration, false);
  return readImage();
}

Image Restir::readImage() const { return readAccumulation(output_, scene_.camera.width, scene_.camera.height); }

void Restir::render(int frame, uint32_t sequence, uint32_t iteration, bool accumulate) {
  PLUME_CHECK(iteration < kMaxIterations);
  const uint32_t key = uint32_t(frame) * kMaxIterations + iteration;
  fillFrame(frame, sequence, key);
  const bool temporal = params_.historyValid != 0u;
  std::vector<std::string> labels;
  uint32_t finalSet = 0;
  uint32_t tailDispatched = 0;
  shared::RsPush tailPush{};
  if (tail_) resetTailAlive();
  ctx_.submitAndWait([&](VkCommandBuffer cmd) {
    timer_.reset(cmd);
    const uint32_t hist = history_;
    uint32_t cur = (hist + 1) % kSets;
    shared::RsPush push{};
    push.outSet = cur;
    // A pass over the frame's pixels: the walking pipeline over those that may see the volume
    // (the first pixelOrder_.inside of the list), its variant without walks over the others.
    const uint32_t all = uint32_t(pixelOrder_.pixels.size()), inside = pixelOrder_.inside;
    auto over = [&](const gpu::ComputePass& pass, shared::RsPush p, uint32_t begin, uint32_t count) {
      if (count == 0) return;
      p.listBegin = begin;
      p.listCount = count;
      pass.record(cmd, glm::uvec3(count, 1, 1), &p);
    };
    // `classes` > 1: once for each reservoir class, the sets offset (class c of set s is set
    // s + c * RS_SETS): the reuse passes.
    auto both = [&](const gpu::ComputePass& walking, const gpu::ComputePass* outside, const char* label,
                    uint32_t classes = 1) {
      const uint32_t scope = timer_.begin(cmd, label);
      for (uint32_t c = 0; c < classes; ++c) {
        shared::RsPush p = push;
        p.inSet += c * kSets;
        p.historySet += c * kSets;
        p.outSet += c * kSets;
        over(walking, p, 0, outside ? inside : all);
        if (outside) over(*outside, p, inside, all - inside);
      }
      timer_.end(cmd, scope);
    };
    // walksPerDispatch candidate walks per dispatch (lavapipe's loop budget: restir/candidates.glsl);
    // the outside variant's M walks (none of them reaches a vertex) in one.
    if (colourUpdate_) {
      const uint32_t colourScope = timer_.begin(cmd, "restir colour");
      shared::RsPush colourPush = push;
      colourPush.colourStep = colourStep_;
      if (options_.colourTarget) {
        over(*colour_, colourPush, 0, all);
        gpu::computeBarrier(cmd);
      }
      colourPush.colourStep = 2u;
      over(*colour_, colourPush, 0, all);
      colourWritten_ = true;
      timer_.end(cmd, colourScope);
      labels.push_back("colour");
      gpu::computeBarrier(cmd);
    }
    if (lamps_) {  // (its pixels' lamp reservoirs; the candidates pass writes the others')
      const uint32_t lampScope = timer_.begin(cmd, "restir lamps");
      const uint32_t listBegin = all + (all + 31) / 32;
      if (lampsRect_) {
        over(*lamps_, push, listBegin, lampPixels_ - lampRectPixels_);
        over(*lampsRect_, push, lampRectListBegin_, lampRectPixels_);
      } else {
        over(*lamps_, push, listBegin, lampPixels_);
      }
      timer_.end(cmd, lampScope);
      labels.push_back("lamps");
    }
    const uint32_t candidates = timer_.begin(cmd, "restir candidates");
    for (uint32_t m = 0; m < params_.candidates; m += params_.walksPerDispatch) {
      if (m > 0) gpu::computeBarrier(cmd);
      push.candidate = m;
      const gpu::ComputePass& walks = moved_ && candidatesMoving_ ? *candidatesMoving_ : *candidates_;
      over(walks, push, 0, inside);  // (every pixel is inside without the outside variants)
    }
    push.candidate = 0;
    if (candidatesOut_) over(*candidatesOut_, push, inside, all - inside);
    timer_.end(cmd, candidates);
    labels.push_back("candidates");
    gpu::computeBarrier(cmd);
    if (temporal) {
      const uint32_t out = (hist + 2) % kSets;
      push.inSet = cur;
      push.historySet = hist;
      push.outSet = out;
      const bool same = params_.historySameDomain != 0u && options_.sameDomainTemporal;
      // The same-domain pipeline evaluates no target: one dispatch over every pixel.
      if (same) {
        both(*temporalSame_, nullptr, "restir temporal", classes_);
      } else {
        both(*temporal_, temporalOut_.get(), "restir temporal", classes_);
      }
      labels.push_back("temporal");
      gpu::computeBarrier(cmd);
      cur = out;
    }
    for (int r = 0; r < rounds_; ++r) {
      const uint32_t out = (cur + 1) % kSets;
      push.inSet = cur;
      push.historySet = cur;
      push.outSet = out;
      push.spatialRound = uint32_t(r);
      both(*spatial_, spatialOut_.get(), "restir spatial", classes_);
      labels.push_back(strf("spatial %d", r + 1));
      gpu::computeBarrier(cmd);
      cur = out;
    }
    push.inSet = cur;
    push.historySet = cur;
    push.outSet = cur;
    push.spatialRound = 0u;
    push.restartAccumulation = accumulate ? 0u : 1u;
    both(*shade_, shadeOut_.get(), "restir shade");
    labels.push_back("shade");
    tailPush = push;
    if (tail_) tailDispatched = recordTail(cmd, push, 0);
    finalSet = cur;
  });
  passTimes_ = timer_.read();
  if (tail_) labels.push_back("tail");
  for (size_t i = 0; i < passTimes_.size() && i < labels.size(); ++i) passTimes_[i].first = labels[i];
  // The tail goes on, kTailDispatchesPerSubmit dispatches at a time, while a walk is still alive
  // (the last dispatch of each submit counts them): a long max_bounces costs only the dispatches
  // its longest walk needs, not max_bounces / RS_TAIL_SEGMENTS of them.
  while (tail_ && tailDispatched < tailDispatches_ && tailAlive() > 0) {
    ctx_.submitAndWait([&](VkCommandBuffer cmd) {
      timer_.reset(cmd);
      tailDispatched = recordTail(cmd, tailPush, tailDispatched);
    });
    for (const auto& [name, ms] : timer_.read()) passTimes_.back().second += ms;
  }
  if (tail_) passTimes_.back().first = strf("tail x%u", tailDispatched);
  history_ = finalSet;
  hasHistory_ = true;
  prevSequence_ = sequence;
}

// Records the tail's dispatches from `first` on, at most kTailDispatchesPerSubmit of them, the
// last one counting the walks still alive after it (rsCounters[RS_COUNTER_TAIL_ALIVE]); returns
// the number dispatched so far.
uint32_t Restir::recordTail(VkCommandBuffer cmd, shared::RsPush push, uint32_t first) {
  // Over the pixels that may see the volume only: the outside variant of final shading ended
  // the others' walks (their camera rays escape).
  const uint32_t count = pixelOrder_.inside;
  push.listBegin = 0;
  push.listCount = count;
  const uint32_t last = std::min(tailDispatches_, first + kTailDispatchesPerSubmit);
  const uint32_t scope = timer_.begin(cmd, "restir tail");
  for (uint32_t i = first; i < last; ++i) {
    gpu::computeBarrier(cmd);
    push.countAlive = i + 1 == last ? 1u : 0u;
    if (count > 0) tail_->record(cmd, glm::uvec3(count, 1, 1), &push);
  }
  timer_.end(cmd, scope);
  return last;
}

uint32_t Restir::tailAlive() {
  uint32_t alive = 0;
  counters_.download(&alive, sizeof alive, shared::RS_COUNTER_TAIL_ALIVE * sizeof(uint32_t));
  resetTailAlive();
  return alive;
}

void Restir::resetTailAlive() {
  const uint32_t zero = 0;
  counters_.upload(&zero, sizeof zero, shared::RS_COUNTER_TAIL_ALIVE * sizeof(uint32_t));
}

uint32_t Restir::takeDroppedCount() {
  uint32_t dropped = 0;
  counters_.download(&dropped, sizeof dropped);
  const uint32_t zero = 0;
  counters_.upload(&zero, sizeof zero);
  return dropped;
}

double Restir::lastFrameGpuMs() const {
  double ms = 0;
  for (const auto& [name, t] : passTimes_) ms += t;
  return ms;
}

}  // namespace plume
