#include "bench/kernels.h"

#include "core/error.h"
#include "core/log.h"
#include "media/vdb_loader.h"
#include "reference/counters.h"
#include "reference/reference.h"
#include "render/estimator.h"
#include "render/volume_source.h"
#include "shaders/shared/kernel_counters.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>

namespace plume {
namespace {

namespace fs = std::filesystem;
namespace sh = shared;

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const double at = q * double(v.size() - 1);
  const size_t i = size_t(at);
  return i + 1 < v.size() ? v[i] + (at - double(i)) * (v[i + 1] - v[i]) : v[i];
}

struct Line {
  double slope = 0, intercept = 0;
  double slopeLow = 0, slopeHigh = 0;  // quartiles of the pairwise slopes
};

// The Theil-Sen line through (x, y): the median of the slopes of all pairs with different x, and
// the median of y - slope x. Robust to the outliers a loaded machine produces (a run that shared
// its cores with another process), where least squares is not.
Line fitLine(const std::vector<double>& x, const std::vector<double>& y) {
  std::vector<double> slopes;
  for (size_t i = 0; i < x.size(); ++i)
    for (size_t j = i + 1; j < x.size(); ++j)
      if (x[i] != x[j]) slopes.push_back((y[j] - y[i]) / (x[j] - x[i]));
  Line l;
  if (slopes.empty()) {
    if (!x.empty() && x[0] != 0) l.slope = l.slopeLow = l.slopeHigh = y[0] / x[0];
    return l;
  }
  l.slope = median(slopes);
  l.slopeLow = quantile(slopes, 0.25);
  l.slopeHigh = quantile(slopes, 0.75);
  std::vector<double> rest;
  for (size_t i = 0; i < x.size(); ++i) rest.push_back(y[i] - l.slope * x[i]);
  l.intercept = median(rest);
  return l;
}

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// The walk's trackers (VOL_TRACK_* of shaders/volume/walk.glsl), by counter block.
const char* kTrackerNames[sh::KC_TRACKERS] = {"delta tracking",   "ratio tracking (NEE)", "residual ratio tracking",
                                              "mean-field depth", "mean-field sampling",  "delta tracking + emission",
                                              "ratio tracking + emission", "residual ratio, segments"};
bool isTracking(uint32_t t) { return t == 0 || t == 4 || t == 5; }  // free flights (4: in the mean field)
bool isTransmittance(uint32_t t) { return t == 1 || t == 2 || t == 6 || t == 7; }  // transmittance estimates

double ratio(double a, double b) { return b > 0 ? a / b : 0; }

// A device run's counter words as loops per image-wide sample; lanes from the subgroup words.
void deviceLoops(const std::vector<uint64_t>& w, double samples, KernelRow& row) {
  double seg = 0, segIt = 0, stepL = 0, stepIt = 0, trL = 0, trIt = 0, lk = 0, lkIt = 0;
  for (uint32_t t = 0; t < sh::KC_TRACKERS; ++t) {
    const uint64_t* c = &w[sh::KC_BASE + t * sh::KC_PER_TRACKER];
    if (c[sh::KC_WALKS] == 0) continue;
    KernelLoop l;
    l.name = kTrackerNames[t];
    l.walks = c[sh::KC_WALKS] / samples;
    l.segments = c[sh::KC_SEGMENTS] / samples;
    l.steps = c[sh::KC_STEPS] / samples;
    l.lookups = c[sh::KC_LOOKUPS] / samples;
    l.segmentLanes = ratio(double(c[sh::KC_SEGMENTS]), double(c[sh::KC_SEGMENT_ITERS]));
    l.stepLanes = ratio(double(c[sh::KC_STEPS]), double(c[sh::KC_STEP_ITERS]));
    l.lookupLanes = ratio(double(c[sh::KC_LOOKUPS]), double(c[sh::KC_LOOKUP_ITERS]));
    row.loops.push_back(l);
    row.total.walks += l.walks, row.total.segments += l.segments, row.total.steps += l.steps, row.total.lookups += l.lookups;
    seg += c[sh::KC_SEGMENTS], segIt += c[sh::KC_SEGMENT_ITERS];
    lk += c[sh::KC_LOOKUPS], lkIt += c[sh::KC_LOOKUP_ITERS];
    if (isTracking(t)) stepL += c[sh::KC_STEPS], stepIt += c[sh::KC_STEP_ITERS];
    if (isTransmittance(t)) trL += c[sh::KC_STEPS], trIt += c[sh::KC_STEP_ITERS];
  }
  row.trackingLanes = ratio(stepL, stepIt);
  row.transmittanceLanes = ratio(trL, trIt);
  row.ddaLanes = ratio(seg, segIt);
  row.lookupLanes = ratio(lk, lkIt);
}

void referenceLoops(const ref::KernelCounts& k, double samples, KernelRow& row) {
  for (const auto& [name, c] : {std::pair<const char*, const ref::WalkCounts&>{"delta tracking", k.collision},
                                {"ratio tracking (NEE)", k.transmittance}}) {
    if (c.walks == 0) continue;
    KernelLoop l;
    l.name = name;
    l.walks = c.walks / samples;
    l.segments = c.segments / samples;
    l.steps = c.steps / samples;
    l.lookups = c.lookups / samples;
    row.loops.push_back(l);
    row.total.walks += l.walks, row.total.segments += l.segments, row.total.steps += l.steps, row.total.lookups += l.lookups;
  }
}

// A method: run(k) renders k samples (iterations) and returns the wall ms; count() fills the row's
// events from a separate counting run.
struct Method {
  KernelRow row;
  std::function<double(int)> run;
  std::function<void(KernelRow&)> count;
  std::vector<std::vector<double>> ms;  // [k index][round]
};

std::string fmt(double v, const char* f = "%.3g") { return v > 0 ? strf(f, v) : "—"; }

std::string markdownOf(const KernelBenchResult& r, const Scene& scene, const KernelBenchOptions& o, int frame) {
  std::string md = "# Kernel benchmark: " + fs::path(scene.path).filename().string() + "\n\n";
  const std::time_t now = std::time(nullptr);
  char date[32];
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  md += strf("%s; device: %s; frame %d held still, %dx%d, max_bounces %d; k = ", date, r.device.c_str(), frame,
             scene.camera.width, scene.camera.height, scene.render.maxBounces);
  for (size_t i = 0; i < o.spp.size(); ++i) md += strf("%s%d", i ? ", " : "", o.spp[i]);
  md += strf(" samples per run, %d alternating rounds, medians; events from %d counted samples per method.\n\n",
             o.rounds, o.countSpp);
  if (!o.commandLine.empty()) md += "```\n" + o.commandLine + "\n```\n\n";
  md += kernelTable(r);
  md += "\nms/sample: marginal wall ms per image-wide sample (ReSTIR: per iteration), the Theil-Sen slope of "
        "the wall time of every run against its k (the median of the pairwise slopes; their quartiles beside it); "
        "fixed: the intercept. Events per second = events per image-wide sample / marginal time. Lanes: mean "
        "active lanes per subgroup iteration (of 8 on lavapipe) in the free-flight tracking loops, the "
        "transmittance loops (NEE ratio tracking, ReSTIR's residual ratio tracking), the DDA's segment loop and "
        "at density lookups; the CPU reference is scalar.\n\n";
  md += "## Per loop (events per image-wide sample)\n\n| method | loop | walks | segments | steps | lookups | lanes: "
        "segments | steps | lookups |\n|---|---|---|---|---|---|---|---|---|\n";
  for (const KernelRow& row : r.rows)
    for (const KernelLoop& l : row.loops)
      md += strf("| %s | %s | %.4g | %.4g | %.4g | %.4g | %s | %s | %s |\n", row.method.c_str(), l.name.c_str(), l.walks,
                 l.segments, l.steps, l.lookups, fmt(l.segmentLanes, "%.2f").c_str(), fmt(l.stepLanes, "%.2f").c_str(),
                 fmt(l.lookupLanes, "%.2f").c_str());
  md += "\n## Wall ms per run (medians)\n\n| method |";
  for (int k : o.spp) md += strf(" k = %d |", k);
  md += "\n|---|";
  for (size_t i = 0; i < o.spp.size(); ++i) md += "---|";
  md += "\n";
  for (const KernelRow& row : r.rows) {
    md += "| " + row.method + " |";
    for (double v : row.medianMs) md += strf(" %.1f |", v);
    md += "\n";
  }
  if (r.overflow) md += "\n**Warning**: a device counter passed 2^31 in one dispatch; the counts are unreliable.\n";
  return md;
}

}  // namespace

std::string kernelTable(const KernelBenchResult& r) {
  std::string t =
      "| method | ms/sample | (quartiles) | fixed ms | M steps/s | M lookups/s | M segments/s | steps/px | lookups/px | "
      "segments/px | lanes: tracking | transmittance | DDA | lookups |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const KernelRow& row : r.rows) {
    t += strf("| %s | %.2f | %.2f-%.2f | %.1f | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |\n", row.method.c_str(),
              row.msPerSample, row.msPerSampleLow, row.msPerSampleHigh, row.fixedMs, fmt(row.perSecond(row.total.steps) * 1e-6, "%.1f").c_str(),
              fmt(row.perSecond(row.total.lookups) * 1e-6, "%.1f").c_str(),
              fmt(row.perSecond(row.total.segments) * 1e-6, "%.1f").c_str(), fmt(row.total.steps / r.pixels, "%.1f").c_str(),
              fmt(row.total.lookups / r.pixels, "%.1f").c_str(), fmt(row.total.segments / r.pixels, "%.1f").c_str(),
              fmt(row.trackingLanes, "%.2f").c_str(), fmt(row.transmittanceLanes, "%.2f").c_str(),
              fmt(row.ddaLanes, "%.2f").c_str(), fmt(row.lookupLanes, "%.2f").c_str());
  }
  return t;
}

KernelBenchResult runKernelBench(gpu::Context& ctx, gpu::ShaderCompiler& compiler, const Scene& scene,
                                 const KernelBenchOptions& o) {
  if (o.spp.empty() || *std::min_element(o.spp.begin(), o.spp.end()) < 1) throw InputError("bench --kernels: --kernel-spp needs k >= 1");
  KernelBenchResult result;
  result.device = ctx.deviceName();
  result.pixels = double(scene.camera.width) * scene.camera.height;
  const int frame = o.gridFrame >= 0 ? o.gridFrame : scene.render.frameFirst;
  const int maxK = *std::max_element(o.spp.begin(), o.spp.end());
  VolumeSource volumes(ctx, scene.medium(), {});
  const GpuVolumeResources& volume = volumes.load(frame);

  std::vector<Method> methods;
  std::vector<std::unique_ptr<Scene>> scenes;  // outlive their estimators
  std::vector<std::unique_ptr<Estimator>> estimators;
  auto estimator = [&](const char* mode, bool counters) -> Estimator& {
    scenes.push_back(std::make_unique<Scene>(scene));
    scenes.back()->render.mode = mode;
    const EstimatorKind kind = estimatorKind(scenes.back()->render);
    if (estimatorTraits(kind).check) estimatorTraits(kind).check(*scenes.back());
    estimators.push_back(makeEstimator(kind, ctx, compiler, *scenes.back(), {.batch = maxK, .kernelCounters = counters}));
    estimators.back()->setVolumes(volume, nullptr);  // the grid held still
    return *estimators.back();
  };
  bool overflow = false;
  // The device's counters over `n` dispatches of one sample (iteration) each, per image-wide sample.
  auto countDevice = [&](Estimator& e, int n, KernelRow& row) {
    std::vector<uint64_t> sum(sh::KC_WORDS, 0);
    e.beginFrame(frame);
    for (int i = 0; i < n; ++i) {
      const std::vector<uint32_t> before = volume.counterWords();
      e.addSamples(1);
      const std::vector<uint32_t> after = volume.counterWords();
      for (uint32_t w = 0; w < sh::KC_WORDS; ++w) {
        const uint32_t d = after[w] - before[w];  // modulo 2^32
        overflow |= d >= (1u << 31);
        sum[w] += d;
      }
    }
    deviceLoops(sum, n, row);
  };
  auto timed = [](Estimator& e, int f) {
    return [&e, f](int k) {
      const auto t0 = std::chrono::steady_clock::now();
      e.renderFrame(f, k, {});
      return msSince(t0);
    };
  };

  {
    Method m;
    m.row.method = "path tracer";
    m.run = timed(estimator("pt", false), frame);
    Estimator* counting = &estimator("pt", true);
    m.count = [&, counting](KernelRow& row) { countDevice(*counting, o.countSpp, row); };
    methods.push_back(std::move(m));
  }
  if (o.restir) {
    const std::string mode = scene.render.mode.rfind("restir", 0) == 0 ? scene.render.mode : "restir";
    Method m;
    m.row.method = "ReSTIR iteration";
    m.run = timed(estimator(mode.c_str(), false), frame);
    Estimator* counting = &estimator(mode.c_str(), true);
    m.count = [&, counting](KernelRow& row) { countDevice(*counting, o.countSpp, row); };
    methods.push_back(std::move(m));
  }
  LoadedGrid grid;
  openvdb::FloatGrid::ConstPtr emission;  // loaded once, not at every run
  if (o.reference) {
    ref::checkReferenceSupports(scene);
    const Medium& medium = scene.medium();
    grid = loadFloatGrid(medium.vdbPath(frame), medium.densityGrid);
    grid.clampedValues = clampOpticalDepth(*grid.grid, medium.densityScale);
    if (medium.emission) emission = loadFloatGrid(medium.vdbPath(frame), medium.emission->grid).grid;
    auto renderRef = [&, frame](int k) {
      Scene s = scene;
      s.render.spp = k;
      ref::ReferenceOptions opt;
      opt.frame = frame;
      opt.emission = emission;
      opt.progress = false;
      ref::renderReference(s, grid.grid, opt);
    };
    Method m;
    m.row.method = "CPU reference";
    m.run = [renderRef](int k) {
      const auto t0 = std::chrono::steady_clock::now();
      renderRef(k);
      return msSince(t0);
    };
    m.count = [&, renderRef](KernelRow& row) {
      ref::setKernelCounting(true);
      renderRef(o.countSpp);
      const ref::KernelCounts k = ref::kernelCounts();
      ref::setKernelCounting(false);
      referenceLoops(k, o.countSpp, row);
    };
    methods.push_back(std::move(m));
  }

  // Warm-up (shader compilation, first-touch allocations, caches), then alternating rounds.
  for (Method& m : methods) m.run(1), m.ms.assign(o.spp.size(), {});
  for (int r = 0; r < o.rounds; ++r) {
    for (size_t i = 0; i < o.spp.size(); ++i) {
      // Each round visits k in the other order as well, so drifting load does not tilt the slope.
      const size_t ki = r % 2 ? o.spp.size() - 1 - i : i;
      for (Method& m : methods) m.ms[ki].push_back(m.run(o.spp[ki]));
    }
    logInfo(strf("bench --kernels: round %d of %d done", r + 1, o.rounds));
  }
  for (Method& m : methods) {
    std::vector<double> x, y;  // every run
    for (size_t i = 0; i < o.spp.size(); ++i) {
      m.row.medianMs.push_back(median(m.ms[i]));
      for (double v : m.ms[i]) x.push_back(o.spp[i]), y.push_back(v);
    }
    const Line line = fitLine(x, y);
    m.row.msPerSample = line.slope;
    m.row.fixedMs = line.intercept;
    m.row.msPerSampleLow = line.slopeLow;
    m.row.msPerSampleHigh = line.slopeHigh;
    m.count(m.row);
    result.rows.push_back(m.row);
  }
  result.overflow = overflow;
  if (overflow) logWarn("bench --kernels: a device counter passed 2^31 in one dispatch: the counts are unreliable");

  const std::string dir = o.outDir.empty() ? (fs::path(scene.dir) / "bench_out").string() : o.outDir;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw InputError("bench: cannot create " + dir + ": " + ec.message());
  result.markdown = markdownOf(result, scene, o, frame);
  result.mdPath = (fs::path(dir) / strf("%s_kernels_%dx%d.md", fs::path(scene.path).stem().string().c_str(),
                                        scene.camera.width, scene.camera.height))
                      .string();
  std::ofstream(result.mdPath) << result.markdown;
  return result;
}

}  // namespace plume
