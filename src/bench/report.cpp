#include "bench/report.h"

#include "core/log.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

namespace plume {
namespace {

namespace fs = std::filesystem;

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
  s += strf("<text x='%.0f' y='%.0f'>time per frame (ms, log; GPU timestamps, CPU reference: wall)</text>", L + 60, H - 20);
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
  const char* cpuColour = "#1f77b4";
  // The path tracer's and the CPU reference's points are curves (one method at several spp).
  for (const auto& [prefix, colour] : {std::pair{"pt ", "black"}, std::pair{"reference ", cpuColour}}) {
    for (const char* cam : {"static", "moving"}) {
      std::string line;
      for (const auto& r : rows)
        if (r.camera == cam && r.method.rfind(prefix, 0) == 0) line += strf("%.1f,%.1f ", X(r.frameMs), Y(r.relMse));
      if (!line.empty())
        s += strf("<polyline points='%s' fill='none' stroke='%s' %s/>\n", line.c_str(), colour,
                  std::string(cam) == "moving" ? "stroke-dasharray='4 3'" : "");
    }
  }
  int legend = 0;
  std::map<std::string, int> colourOf;  // ReSTIR variants: their colour's index; the two curves: -1
  int variantColours = 0;
  for (const auto& r : rows) {
    const bool pt = r.method.rfind("pt ", 0) == 0;
    const bool cpu = r.method.rfind("reference ", 0) == 0;
    const std::string key = pt ? "path tracer" : cpu ? "CPU reference" : r.method;
    if (!colourOf.count(key)) colourOf[key] = pt || cpu ? -1 : variantColours++;
    const char* c = pt ? "black" : cpu ? cpuColour : colours[colourOf[key] % 8];
    if (r.camera == "static") s += strf("<circle cx='%.1f' cy='%.1f' r='4' fill='%s'/>", X(r.frameMs), Y(r.relMse), c);
    else s += strf("<rect x='%.1f' y='%.1f' width='7' height='7' fill='none' stroke='%s'/>", X(r.frameMs) - 3.5, Y(r.relMse) - 3.5, c);
  }
  for (const auto& [key, i] : colourOf) {
    const char* c = key == "path tracer" ? "black" : key == "CPU reference" ? cpuColour : colours[i % 8];
    s += strf("<circle cx='%.0f' cy='%.0f' r='4' fill='%s'/><text x='%.0f' y='%.0f'>%s</text>\n", W - R + 15, T + 16.0 * legend, c,
              W - R + 24, T + 16.0 * legend + 4, key.c_str());
    ++legend;
  }
  s += strf("<text x='%.0f' y='%.0f'>filled: static camera; open squares, dashed: moving</text>\n", W - R + 10, T + 16.0 * legend + 10);
  return s + "</svg>\n";
}

}  // namespace

void writeBenchReport(BenchResult& result, const Scene& scene, const BenchOptions& o, int first, const std::string& dir) {
  std::string md = strf("Device: %s. Scene: %s, %dx%d, max_bounces %d, the grid of frame %d held still. Seed %lld. Warm-up %d "
                        "frames%s, %d measured; medians. Converged image: GPU path tracer, %d spp (own relMSE <= %.2g). ms/frame: GPU "
                        "timestamps; the CPU reference's rows (`reference N spp`, its own seed): wall time, on the "
                        "host's cores.\n\n",
                        result.device.c_str(), scene.path.c_str(), scene.camera.width, scene.camera.height,
                        scene.render.maxBounces, first, (long long)scene.render.seed, result.warmup,
                        result.warmupMoving != result.warmup ? strf(" (moving camera: %d)", result.warmupMoving).c_str() : "",
                        o.frames, o.refSpp, result.referenceRelMse);
  md += "| camera | method | ms/frame | relMSE | PT relMSE at equal time | gain vs PT | per-pass ms |\n";
  md += "|---|---|---|---|---|---|---|\n";
  std::string csv = "camera,method,frame_ms,relmse,pt_relmse_equal_time,gain\n";
  for (const BenchRow& r : result.rows) {
    const bool pt = r.method.rfind("pt ", 0) == 0;
    md += strf("| %s | %s | %.1f | %.4g | %s | %s | %s |\n", r.camera.c_str(), r.method.c_str(), r.frameMs, r.relMse,
               pt ? "" : strf("%.4g%s", r.ptRelMseAtEqualTime, r.outsidePtRange ? "*" : "").c_str(),
               pt ? "" : strf("%.2fx", r.gain).c_str(),
               r.passTimes.c_str());
    csv += strf("%s,%s,%.4f,%.6g,%.6g,%.4f\n", r.camera.c_str(), r.method.c_str(), r.frameMs, r.relMse,
                r.ptRelMseAtEqualTime, r.gain);
  }
  if (std::any_of(result.rows.begin(), result.rows.end(), [](const BenchRow& r) { return r.outsidePtRange; }))
    md += "\n\\* outside the path tracer's measured times: its nearest point's relMSE scaled by 1/time.\n";
  result.markdown = md;
  const std::string stem = fs::path(scene.path).stem().string();
  result.mdPath = (fs::path(dir) / (stem + "_bench.md")).string();
  result.csvPath = (fs::path(dir) / (stem + "_bench.csv")).string();
  result.svgPath = (fs::path(dir) / (stem + "_bench.svg")).string();
  std::ofstream(result.mdPath) << md;
  std::ofstream(result.csvPath) << csv;
  std::ofstream(result.svgPath) << svgPlot(result.rows, "relMSE against GPU time per frame: " + stem + " (" + result.device + ")");
}

}  // namespace plume
