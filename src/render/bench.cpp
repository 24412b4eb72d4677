#include "render/bench.h"

#include "core/error.h"
#include "core/hash.h"
#include "core/log.h"
#include "core/stats.h"
#include "io/image.h"
#include "render/estimator.h"
#include "render/volume_source.h"
#include "scene/render_key.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
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
// render setting the path tracer reads; not mode, spp, seed or the ReSTIR settings), and the
// grid file's size and time. An edited scene or a re-baked grid gets a new reference, never a
// stale one; tuning ReSTIR in the scene file keeps the cached one.
uint64_t referenceKey(const Scene& s, int gridFrame) {
  const RenderKey render = sceneRenderKey(s, gridFrame, [](const std::string& k) {
    return k != "mode" && k != "spp" && k != "seed" && k.rfind("restir_", 0) != 0;
  });
  std::error_code ec;
  const fs::path vdb = s.medium().vdbPath(gridFrame);
  const auto size = fs::file_size(vdb, ec);
  const auto time = fs::last_write_time(vdb, ec).time_since_epoch().count();
  return fnv1a(render.text() + strf("|%llu|%lld", (unsigned long long)size, (long long)time));
}

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
  rs.render.seed = 987654321;
  std::unique_ptr<Estimator> pt = makeEstimator(EstimatorKind::PathTracer, ctx, compiler, rs, {.batch = 32});
  pt->setVolumes(volume, nullptr);
  pt->renderFrame(frame, refSpp, {});
  Image ref = pt->readImage();
  makeFolder(fs::path(path).parent_path());
  writeExr(path, ref);
  return ref;
}

// A ReSTIR variant as the render settings that select it (mode restir-biased for RS_MIS_BIASED).
RenderSettings withRestir(RenderSettings rs, const RestirOptions& v) {
  rs.mode = v.mis == shared::RS_MIS_BIASED ? "restir-biased" : "restir";
  rs.restirMis = v.mis == shared::RS_MIS_GBH ? "gbh" : "pairwise";
  rs.restirCandidates = v.candidates;
  rs.restirNeighbours = v.neighbours;
  rs.restirRadius = v.radius;
  rs.restirRounds = v.rounds;
  rs.restirHistoryCap = v.historyCap;
  return rs;
}

struct Method {
  std::string name;
  bool pathTracer = false;  // a point of the path tracer's curve
  int spp = 1;              // per frame (ReSTIR: one iteration)
  std::unique_ptr<Scene> scene;  // its settings; outlives the estimator
  std::unique_ptr<Estimator> estimator;
  std::vector<double> ms, err;
  std::map<std::string, std::vector<double>> passMs;
};

// log-log interpolation of the path tracer's (ms, relMSE) points at `ms`.
double ptCurveAt(const std::vector<std::pair<double, double>>& pts, double ms) {
  if (pts.empty()) return 0;
  if (pts.size() == 1) return pts[0].second * pts[0].first / ms;
  size_t i = 0;
  while (i + 2 < pts.size() && pts[i + 1].first < ms) ++i;
  const double x0 = std::log(pts[i].first), x1 = std::log(pts[i + 1].first);
  const double y0 = std::log(pts[i].second), y1 = std::log(pts[i + 1].second);
  const double t = (std::log(ms) - x0) / (x1 - x0);
  return std::exp(y0 + t * (y1 - y0));
}

std::string svgPlot(const std::vector<BenchRow>& rows, const std::string& title) {
  double xmin = 1e30, xmax = 0, ymin = 1e30, ymax = 0;
  for (const auto& r : rows) {
    if (!(r.frameMs > 0 && r.relMse > 0)) continue;
    xmin = std::min(xmin, r.frameMs), xmax = std::max(xmax, r.frameMs);
    ymin = std::min(ymin, r.relMse), ymax = std::max(ymax, r.relMse);
  }
  if (xmax <= 0) return "<svg xmlns='http://www.w3.org/2000/svg'/>";
  const double W = 760, H = 480, L = 80, R = 230, T = 40, B = 60;
  auto X = [&](double v) { return L + (std::log10(v) - std::log10(xmin / 1.2)) / (std::log10(xmax * 1.2) - std::log10(xmin / 1.2)) * (W - L - R); };
  auto Y = [&](double v) { return H - B - (std::log10(v) - std::log10(ymin / 1.5)) / (std::log10(ymax * 1.5) - std::log10(ymin / 1.5)) * (H - T - B); };
  std::string s = strf("<svg xmlns='http://www.w3.org/2000/svg' width='%.0f' height='%.0f' font-family='sans-serif' font-size='11'>\n", W, H);
  s += strf("<rect width='100%%' height='100%%' fill='white'/><text x='%.0f' y='22' font-size='14'>%s</text>\n", L, title.c_str());
  s += strf("<line x1='%.0f' y1='%.0f' x2='%.0f' y2='%.0f' stroke='black'/>", L, H - B, W - R, H - B);
  s += strf("<line x1='%.0f' y1='%.0f' x2='%.0f' y2='%.0f' stroke='black'/>\n", L, T, L, H - B);
  s += strf("<text x='%.0f' y='%.0f'>GPU time per frame (ms, log)</text>", L + 150, H - 20);
  s += strf("<text x='12' y='%.0f' transform='rotate(-90 12 %.0f)'>relMSE (log)</text>\n", H / 2 + 40, H / 2 + 40);
  for (int e = int(std::floor(std::log10(ymin / 1.5))); e <= int(std::ceil(std::log10(ymax * 1.5))); ++e) {
    const double v = std::pow(10.0, e);
    if (v < ymin / 1.5 || v > ymax * 1.5) continue;
    s += strf("<text x='%.0f' y='%.0f' text-anchor='end'>1e%d</text>", L - 4, Y(v) + 4, e);
  }
  for (int e = int(std::floor(std::log10(xmin / 1.2))); e <= int(std::ceil(std::log10(xmax * 1.2))); ++e) {
    for (double m : {1.0, 2.0, 5.0}) {
      const double v = m * std::pow(10.0, e);
      if (v < xmin / 1.2 || v > xmax * 1.2) continue;
      s += strf("<text x='%.0f' y='%.0f' text-anchor='middle'>%g</text>", X(v), H - B + 14, v);
    }
  }
  const char* colours[] = {"#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf", "#8c564b", "#e377c2", "#bcbd22"};
  for (const char* cam : {"static", "moving"}) {
    std::string line;
    for (const auto& r : rows)
      if (r.camera == cam && r.method.rfind("pt ", 0) == 0) line += strf("%.1f,%.1f ", X(r.frameMs), Y(r.relMse));
    if (!line.empty())
      s += strf("<polyline points='%s' fill='none' stroke='black' %s/>\n", line.c_str(),
                std::string(cam) == "moving" ? "stroke-dasharray='4 3'" : "");
  }
  int legend = 0;
  std::map<std::string, int> colourOf;
  for (const auto& r : rows) {
    const bool pt = r.method.rfind("pt ", 0) == 0;
    const std::string key = pt ? "path tracer" : r.method;
    if (!colourOf.count(key)) colourOf[key] = int(colourOf.size());
    const char* c = pt ? "black" : colours[colourOf[key] % 8];
    if (r.camera == "static") s += strf("<circle cx='%.1f' cy='%.1f' r='4' fill='%s'/>", X(r.frameMs), Y(r.relMse), c);
    else s += strf("<rect x='%.1f' y='%.1f' width='7' height='7' fill='none' stroke='%s'/>", X(r.frameMs) - 3.5, Y(r.relMse) - 3.5, c);
  }
  for (const auto& [key, i] : colourOf) {
    const char* c = key == "path tracer" ? "black" : colours[i % 8];
    s += strf("<circle cx='%.0f' cy='%.0f' r='4' fill='%s'/><text x='%.0f' y='%.0f'>%s</text>\n", W - R + 15, T + 16.0 * legend, c,
              W - R + 24, T + 16.0 * legend + 4, key.c_str());
    ++legend;
  }
  s += strf("<text x='%.0f' y='%.0f'>filled: static camera; open squares, dashed: moving</text>\n", W - R + 10, T + 16.0 * legend + 10);
  return s + "</svg>\n";
}

}  // namespace

BenchResult runBench(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const Scene& scene, const BenchOptions& o) {
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
    // restir-biased.
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
    v = base, v.mis = shared::RS_MIS_BIASED;
    add(v);
  }
  if (!o.only.empty()) {
    std::erase_if(variants, [&](const auto& v) {
      return std::none_of(o.only.begin(), o.only.end(), [&](const std::string& k) { return v.first.find(k) != std::string::npos; });
    });
    if (variants.empty()) throw InputError("bench: no ReSTIR variant matches --only");
  }
  // One frame's grid (the first of the scene's range unless chosen), held still: the bench measures
  // the estimators, not the animation. Frame numbers count from it.
  const int first = o.gridFrame >= 0 ? o.gridFrame : scene.render.frameFirst;
  const int last = first + o.warmup + o.frames - 1;
  VolumeSource volumes(ctx, scene.medium(), {});
  const GpuVolumeResources& volume = volumes.load(first);

  for (const bool moving : {false, true}) {
    const std::string cam = moving ? "moving" : "static";
    if (std::find(o.cameras.begin(), o.cameras.end(), cam) == o.cameras.end()) continue;
    Scene s = withCamera(scene, moving, first, last, o.orbitDegPerFrame);
    std::map<int, Image> refs;
    for (int f = first + o.warmup; f <= last; ++f) {
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
    // Alternating: every method renders frame f before any renders f + 1.
    for (int f = first; f <= last; ++f) {
      for (Method& m : methods) {
        const bool warmup = f < first + o.warmup;  // rendered, not read back
        m.estimator->renderFrame(f, m.spp, {});
        if (warmup) continue;
        const Image im = m.estimator->readImage();
        double ms = 0;
        for (const auto& [n, t] : m.estimator->lastPassTimes()) ms += t, m.passMs[n].push_back(t);
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
        row.gain = row.relMse > 0 ? row.ptRelMseAtEqualTime / row.relMse : 0;
      }
      for (const auto& [n, t] : m.passMs) row.passTimes += strf("%s%s %.1f", row.passTimes.empty() ? "" : ", ", n.c_str(), median(t));
      result.rows.push_back(row);
    }
  }

  // Outputs.
  std::string md = strf("Device: %s. Scene: %s, %dx%d, max_bounces %d, the grid of frame %d held still. Warm-up %d "
                        "frames, %d measured; medians. Reference: GPU path tracer, %d spp (own relMSE <= %.2g).\n\n",
                        result.device.c_str(), scene.path.c_str(), scene.camera.width, scene.camera.height,
                        scene.render.maxBounces, first, o.warmup, o.frames, o.refSpp, result.referenceRelMse);
  md += "| camera | method | GPU ms/frame | relMSE | PT relMSE at equal time | gain vs PT | per-pass ms |\n";
  md += "|---|---|---|---|---|---|---|\n";
  std::string csv = "camera,method,frame_ms,relmse,pt_relmse_equal_time,gain\n";
  for (const BenchRow& r : result.rows) {
    const bool pt = r.method.rfind("pt ", 0) == 0;
    md += strf("| %s | %s | %.1f | %.4g | %s | %s | %s |\n", r.camera.c_str(), r.method.c_str(), r.frameMs, r.relMse,
               pt ? "" : strf("%.4g", r.ptRelMseAtEqualTime).c_str(), pt ? "" : strf("%.2fx", r.gain).c_str(),
               r.passTimes.c_str());
    csv += strf("%s,%s,%.4f,%.6g,%.6g,%.4f\n", r.camera.c_str(), r.method.c_str(), r.frameMs, r.relMse,
                r.ptRelMseAtEqualTime, r.gain);
  }
  result.markdown = md;
  const std::string stem = fs::path(scene.path).stem().string();
  result.mdPath = (fs::path(dir) / (stem + "_bench.md")).string();
  result.csvPath = (fs::path(dir) / (stem + "_bench.csv")).string();
  result.svgPath = (fs::path(dir) / (stem + "_bench.svg")).string();
  std::ofstream(result.mdPath) << md;
  std::ofstream(result.csvPath) << csv;
  std::ofstream(result.svgPath) << svgPlot(result.rows, "relMSE against GPU time per frame: " + stem + " (" + result.device + ")");
  return result;
}

}  // namespace plume
