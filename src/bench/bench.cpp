#include "bench/bench.h"

#include "bench/report.h"

#include "core/error.h"
#include "core/hash.h"
#include "core/log.h"
#include "core/stats.h"
#include "io/image.h"
#include "media/vdb_loader.h"
#include "reference/reference.h"
#include "render/estimator.h"
#include "render/volume_source.h"
#include "scene/render_key.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>

namespace plume {
namespace {

namespace fs = std::filesystem;

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// A copy of the scene whose camera orbits its look-at point (moving) or stands still.
Scene withCamera(const Scene& scene, bool moving, int first, int last, float degPerFrame) {
  Scene s = scene;
  s.camera.keys.clear();
  s.camera.baseFrame = first;
  if (!moving) return s;
  for (int f = first + 1; f <= last; ++f) {
    CameraKey k;
    k.frame = f;
    k.pose = scene.camera.base;
    const float a = glm::radians(degPerFrame * float(f - first));
    const glm::vec3 r = scene.camera.base.position - scene.camera.base.lookAt;
    k.pose.position = scene.camera.base.lookAt + glm::vec3(std::cos(a) * r.x + std::sin(a) * r.z, r.y,
                                                           -std::sin(a) * r.x + std::cos(a) * r.z);
    s.camera.keys.push_back(k);
  }
  return s;
}

double referenceOwnRelMse(const Image& ref) {
  double sum = 0;
  for (size_t i = 0; i < ref.rgb.size(); ++i) sum += ref.var[i] / (double(ref.rgb[i]) * ref.rgb[i] + 1e-2);
  return ref.rgb.empty() ? 0 : sum / double(ref.rgb.size());
}

// Creates a folder (and its parents); an unwritable place is bad input, not a crash.
void makeFolder(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw InputError("bench: cannot create " + dir.string() + ": " + ec.message());
}

// What the reference's pixels depend on besides its file name's fields: the path tracer's render
// key of the frame whose grid is held still (scene/render_key.h: camera, media, lights, every
// render setting the path tracer reads; not mode, spp, seed, density_filter (it is always exact)
// or the ReSTIR settings), and the grid file's size and time. An edited scene or a re-baked grid gets a new reference, never a
// stale one; tuning ReSTIR in the scene file keeps the cached one.
uint64_t referenceKey(const Scene& s, int gridFrame) {
  const RenderKey render = sceneRenderKey(s, gridFrame, [](const std::string& k) {
    return k != "mode" && k != "spp" && k != "seed" && k != "density_filter" && k.rfind("restir_", 0) != 0;
  });
  std::error_code ec;
  const fs::path vdb = s.medium().vdbPath(gridFrame);
  const auto size = fs::file_size(vdb, ec);
  const auto time = fs::last_write_time(vdb, ec).time_since_epoch().count();
  return fnv1a(render.text() + strf("|%llu|%lld", (unsigned long long)size, (long long)time));
}

// The converged image's seed; the CPU reference's rows use any other (its pixels' streams would
// repeat the converged image's noise if the two shared an implementation; they do not, but the
// error must not depend on that).
constexpr int kConvergedSeed = 987654321;

// The reference of `frame` (the GPU path tracer at refSpp), cached next to the scene.
Image loadOrBuildReference(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const Scene& s,
                           const GpuVolumeResources& volume, int frame, int refSpp, const std::string& tag) {
  const CameraPose p = s.camera.poseAt(frame);
  const std::string stem = fs::path(s.path).stem().string();
  const std::string path =
      (fs::path(s.dir) / "bench_cache" /
       strf("%s_ref_%s_f%d_%dx%d_spp%d_%.4f_%.4f_%.4f_%016llx.exr", stem.c_str(), tag.c_str(), frame, s.camera.width,
            s.camera.height, refSpp, p.position.x, p.position.y, p.position.z,
            (unsigned long long)referenceKey(s, s.camera.baseFrame)))  // the grid held still
          .string();
  if (fs::exists(path)) return readExr(path);
  logInfo(strf("bench: building the reference %s (%d spp)", path.c_str(), refSpp));
  Scene rs = s;
  rs.render.seed = kConvergedSeed;
  rs.render.densityFilter = "exact";  // the exact field, so a biased option's bias shows in the bench
  std::unique_ptr<Estimator> pt = makeEstimator(EstimatorKind::PathTracer, ctx, compiler, rs, {.batch = 32});
  pt->setVolumes(volume, nullptr);
  pt->renderFrame(frame, refSpp, {});
  Image ref = pt->readImage();
  makeFolder(fs::path(path).parent_path());
  writeExr(path, ref);
  return ref;
}

// Warm-up frames the path tracer renders (before the measured ones, for its caches and pipelines;
// its frames are independent, so the rest of a long ReSTIR warm-up is not rendered).
constexpr int kPathTracerWarmup = 4;

// A ReSTIR variant as the render settings that select it (mode restir-biased for RS_MIS_BIASED).
RenderSettings withRestir(RenderSettings rs, const RestirOptions& v) {
  rs.mode = v.mis == shared::RS_MIS_BIASED ? "restir-biased" : "restir";
  rs.restirMis = v.mis == shared::RS_MIS_GBH ? "gbh" : "pairwise";
  rs.restirCandidates = v.candidates;
  rs.restirCandidatesMoving = v.candidatesMoving;
  rs.restirNeighbours = v.neighbours;
  rs.restirRadius = v.radius;
  rs.restirRounds = v.rounds;
  rs.restirRoundsStatic = v.roundsStatic;
  rs.restirHistoryCap = v.historyCap;
  rs.restirHistoryCapMoving = v.historyCapMoving;
  rs.restirHistoryCapStatic = v.historyCapStatic;
  rs.restirPrefix = v.prefix;
  rs.restirLightCandidates = v.lightCandidates;
  rs.restirLightCandidatesMoving = v.lightCandidatesMoving;
  rs.restirShift = v.reconnect ? "reconnect" : "copy";
  rs.restirTarget = v.colourTarget ? "colour" : "luminance";
  rs.restirEmissionReservoir = v.emissionReservoir ? "own" : "shared";
  return rs;
}

struct Method {
  std::string name;
  bool pathTracer = false;  // a point of the path tracer's curve
  int spp = 1;              // per frame (ReSTIR: one iteration)
  std::unique_ptr<Scene> scene;  // its settings; outlives the estimator
  std::unique_ptr<Estimator> estimator;  // null: the CPU reference (cpuFrame)
  std::function<Image(int frame)> cpuFrame;
  std::vector<double> ms, err;
  std::map<std::string, std::vector<double>> passMs;
};

// log-log interpolation of the path tracer's (ms, relMSE) points at `ms`; outside their range, the
// nearest end point's relMSE scaled by 1/time (an unbiased estimator's error at a proportional
// number of samples), not the end segment's slope, which the noise of two close points can make
// anything (the CPU reference's fast rows lie there).
double ptCurveAt(const std::vector<std::pair<double, double>>& pts, double ms) {
  if (pts.empty()) return 0;
  if (ms <= pts.front().first) return pts.front().second * pts.front().first / ms;
  if (ms >= pts.back().first) return pts.back().second * pts.back().first / ms;
  size_t i = 0;
  while (i + 2 < pts.size() && pts[i + 1].first < ms) ++i;
  const double x0 = std::log(pts[i].first), x1 = std::log(pts[i + 1].first);
  const double y0 = std::log(pts[i].second), y1 = std::log(pts[i + 1].second);
  const double t = (std::log(ms) - x0) / (x1 - x0);
  return std::exp(y0 + t * (y1 - y0));
}

}  // namespace

BenchResult runBench(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const Scene& scene, const BenchOptions& options) {
  BenchOptions o = options;  // the warm-up is filled in below
  BenchResult result;
  result.device = ctx.deviceName();
  const std::string dir = o.outDir.empty() ? (fs::path(scene.dir) / "bench_out").string() : o.outDir;
  makeFolder(dir);
  std::vector<std::pair<std::string, RestirOptions>> variants = o.variants;
  if (variants.empty()) {
    const RestirOptions base = restirOptionsOf(scene.render);
    auto add = [&](RestirOptions v) { variants.emplace_back(v.name(), v); };
    // The scene's settings with pairwise MIS and with the generalised balance heuristic; temporal
    // reuse alone; M 2 and 8; the built-in defaults' 16 px radius (the bundled smoke sets 2 px);
    // with surfaces, the other shift (reconnection or copy); restir-biased.
    RestirOptions v = base;
    v.mis = shared::RS_MIS_PAIRWISE;
    add(v);
    v.mis = shared::RS_MIS_GBH;
    add(v);
    v = base, v.mis = shared::RS_MIS_PAIRWISE, v.rounds = 0;
    add(v);
    for (int m : {2, 8}) {
      v = base, v.mis = shared::RS_MIS_PAIRWISE, v.candidates = m;
      add(v);
    }
    if (base.radius != RestirOptions{}.radius) {
      v = base, v.mis = shared::RS_MIS_PAIRWISE, v.radius = RestirOptions{}.radius;
      add(v);
    }
    if (!scene.surfaces.empty()) {  // the other shift
      v = base, v.mis = shared::RS_MIS_PAIRWISE, v.reconnect = !base.reconnect;
      add(v);
    }
    v = base, v.mis = shared::RS_MIS_BIASED;
    add(v);
  }
  if (!o.only.empty()) {
    std::erase_if(variants, [&](const auto& v) {
      return std::none_of(o.only.begin(), o.only.end(), [&](const std::string& k) { return v.first.find(k) != std::string::npos; });
    });
    if (variants.empty()) throw InputError("bench: no ReSTIR variant matches --only");
  }
  // Warm-up: enough frames for every variant's history to reach its cap (BenchOptions::warmup),
  // each camera's own: a still camera over the still grid runs under the static cap where one is
  // set, a moving one under the still camera's (each frame's own moving cap is at most that).
  auto warmupOf = [&](bool moving) {
    if (o.warmup >= 0) return o.warmup;
    int w = 4;
    for (const auto& [name, v] : variants) w = std::max({w, v.historyCap, moving ? 0 : v.historyCapStatic});
    return w;
  };
  result.warmup = warmupOf(false);
  result.warmupMoving = warmupOf(true);
  // One frame's grid (the first of the scene's range unless chosen), held still: the bench measures
  // the estimators, not the animation. Frame numbers count from it.
  const int first = o.gridFrame >= 0 ? o.gridFrame : scene.render.frameFirst;
  VolumeSource volumes(ctx, scene.medium(), {});
  const GpuVolumeResources& volume = volumes.load(first);
  // The CPU reference's grids of the same frame, sanitised and clamped as `plume reference` does.
  openvdb::FloatGrid::ConstPtr cpuGrid, cpuEmission;
  if (!o.cpuRefSpp.empty()) {
    ref::checkReferenceSupports(scene);
    const Medium& medium = scene.medium();
    LoadedGrid grid = loadFloatGrid(medium.vdbPath(first), medium.densityGrid);
    clampOpticalDepth(*grid.grid, medium.densityScale);
    cpuGrid = grid.grid;
    if (medium.emission) cpuEmission = loadFloatGrid(medium.vdbPath(first), medium.emission->grid).grid;
  }

  for (const bool moving : {false, true}) {
    const std::string cam = moving ? "moving" : "static";
    if (std::find(o.cameras.begin(), o.cameras.end(), cam) == o.cameras.end()) continue;
    const int warmupFrames = moving ? result.warmupMoving : result.warmup;
    const int last = first + warmupFrames + o.frames - 1;
    Scene s = withCamera(scene, moving, first, last, o.orbitDegPerFrame);
    std::map<int, Image> refs;
    for (int f = first + warmupFrames; f <= last; ++f) {
      if (!moving && !refs.empty()) break;
      refs[f] = loadOrBuildReference(ctx, compiler, s, volume, f, o.refSpp, cam);
      result.referenceRelMse = std::max(result.referenceRelMse, referenceOwnRelMse(refs[f]));
    }
    std::vector<Method> methods;
    auto add = [&](Method m, const RenderSettings& rs, int batch) {
      m.scene = std::make_unique<Scene>(s);
      m.scene->render = rs;
      m.estimator = makeEstimator(estimatorKind(rs), ctx, compiler, *m.scene, {.batch = batch});
      m.estimator->setVolumes(volume, nullptr);  // the grid held still
      methods.push_back(std::move(m));
    };
    for (int spp : o.ptSpp) {
      RenderSettings rs = s.render;
      rs.mode = "pt";
      add({.name = strf("pt %d spp", spp), .pathTracer = true, .spp = spp}, rs, spp);  // one dispatch per frame
    }
    for (const auto& [name, v] : variants) add({.name = name}, withRestir(s.render, v), 1);
    for (int spp : o.cpuRefSpp) {
      Method m{.name = strf("reference %d spp", spp), .spp = spp};
      m.scene = std::make_unique<Scene>(s);
      m.scene->render.spp = spp;
      if (m.scene->render.seed == kConvergedSeed) m.scene->render.seed += 1;
      const Scene* rs = m.scene.get();
      m.cpuFrame = [rs, &cpuGrid, &cpuEmission](int f) {
        ref::ReferenceOptions opt;
        opt.frame = f;  // the camera and the random streams of frame f, the grid held still
        opt.emission = cpuEmission;
        opt.progress = false;
        return ref::renderReference(*rs, cpuGrid, opt);
      };
      methods.push_back(std::move(m));
    }
    // Alternating: every method renders frame f before any renders f + 1.
    for (int f = first; f <= last; ++f) {
      for (Method& m : methods) {
        const bool warmup = f < first + warmupFrames;  // rendered, not read back
        Image im;
        double ms = 0;
        if (m.cpuFrame) {
          if (warmup) continue;  // no history to settle
          const auto t0 = std::chrono::steady_clock::now();
          im = m.cpuFrame(f);
          ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        } else {
          // The path tracer has no history either: its last few warm-up frames warm its caches.
          if (m.pathTracer && f < first + warmupFrames - kPathTracerWarmup) continue;
          m.estimator->renderFrame(f, m.spp, {});
          if (warmup) continue;
          im = m.estimator->readImage();
          for (const auto& [n, t] : m.estimator->lastPassTimes()) ms += t, m.passMs[n].push_back(t);
        }
        const Image& ref = moving ? refs.at(f) : refs.begin()->second;
        m.ms.push_back(ms);
        m.err.push_back(relMse(im, ref));
        if (o.saveImages && f == last) {
          std::string file = cam + "_" + m.name + ".exr";
          std::replace(file.begin(), file.end(), ' ', '_');
          writeExr((fs::path(dir) / file).string(), im);
          if (&m == &methods.front()) writeExr((fs::path(dir) / (cam + "_reference.exr")).string(), ref);
        }
      }
    }
    std::vector<std::pair<double, double>> curve;
    for (const Method& m : methods)
      if (m.pathTracer) curve.emplace_back(median(m.ms), median(m.err));
    std::sort(curve.begin(), curve.end());
    for (const Method& m : methods) {
      BenchRow row;
      row.camera = cam;
      row.method = m.name;
      row.frameMs = median(m.ms);
      row.relMse = median(m.err);
      if (!m.pathTracer) {
        row.ptRelMseAtEqualTime = ptCurveAt(curve, row.frameMs);
        row.outsidePtRange = !curve.empty() && (row.frameMs < curve.front().first || row.frameMs > curve.back().first);
        row.gain = row.relMse > 0 ? row.ptRelMseAtEqualTime / row.relMse : 0;
      }
      for (const auto& [n, t] : m.passMs) row.passTimes += strf("%s%s %.1f", row.passTimes.empty() ? "" : ", ", n.c_str(), median(t));
      result.rows.push_back(row);
    }
  }

  // No silent caps: truncated walks and loops cut by the driver (volume/loop_guard.glsl) bias a
  // method's error, so the table is not to be read without this warning.
  if (volume.truncatedCount() + volume.loopLimitCount() > 0) {
    logWarn(strf("bench: %u tracking loops hit the step cap and the driver cut the loops of %u shader invocations: "
                 "the affected rows are biased",
                 volume.truncatedCount(), volume.loopLimitCount()));
  }
  writeBenchReport(result, scene, o, first, dir);
  return result;
}

}  // namespace plume
