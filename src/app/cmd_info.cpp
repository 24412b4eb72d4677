// `plume info FILE.vdb [--bake] [--grid NAME] [--format float16|float32|both]`: what a VDB file
// holds (grids, types, voxel size, bounds, active voxels, value range) and, with --bake, how the
// chosen grid bakes (DESIGN §3): time, throughput, memory per active voxel, structure sizes.
#include "app/commands.h"
#include "core/error.h"
#include "core/log.h"
#include "media/bake.h"
#include "media/vdb_loader.h"

#include <algorithm>
#include <cstdio>
#include <vector>
#include <string>

namespace plume {
namespace {

struct InfoOptions {
  std::string file;
  bool bake = false;
  std::string grid = "density";
  std::string format = "both";
  int repeat = 1;  // bakes per format; the reported time is the median (first bakes warm TBB)
};

void printSummary(const GridSummary& s) {
  std::printf("grid \"%s\"\n", s.name.c_str());
  std::printf("  type            %s%s\n", s.type.c_str(), s.linear ? "" : " (non-linear transform)");
  std::printf("  voxel size      %g %g %g\n", s.voxelSize.x(), s.voxelSize.y(), s.voxelSize.z());
  if (s.activeVoxels == 0) {
    std::printf("  active voxels   0 (empty)\n");
    return;
  }
  const auto& lo = s.indexBounds.min();
  const auto& hi = s.indexBounds.max();
  std::printf("  index bounds    [%d %d %d] .. [%d %d %d] (%d x %d x %d)\n", lo.x(), lo.y(), lo.z(),
              hi.x(), hi.y(), hi.z(), hi.x() - lo.x() + 1, hi.y() - lo.y() + 1, hi.z() - lo.z() + 1);
  const auto& wlo = s.worldBounds.min();
  const auto& whi = s.worldBounds.max();
  std::printf("  world bounds    [%g %g %g] .. [%g %g %g]\n", wlo.x(), wlo.y(), wlo.z(), whi.x(),
              whi.y(), whi.z());
  std::printf("  active voxels   %llu (%llu active tiles)\n", (unsigned long long)s.activeVoxels,
              (unsigned long long)s.activeTiles);
  if (s.type == "float" || s.type == "double" || s.type == "half")
    std::printf("  value range     %g .. %g\n", s.minValue, s.maxValue);
}

void printBake(const BakedVolume& v, int runs) {
  const MemoryReport m = memoryReport(v);
  const double throughput = v.stats.seconds > 0 ? double(v.stats.activeVoxels) / v.stats.seconds : 0;
  std::printf("bake %s\n", texelFormatName(v.format));
  std::printf("  time            %.3f ms%s (%.3g active voxels/s)\n", v.stats.seconds * 1e3,
              runs > 1 ? strf(", median of %d", runs).c_str() : "", throughput);
  std::printf("  bricks          %u allocated of %llu candidates; indirection %d x %d x %d\n",
              v.stats.allocatedBricks, (unsigned long long)v.stats.candidateBricks, v.brickDims.x,
              v.brickDims.y, v.brickDims.z);
  std::printf("  atlas           %d x %d x %d texels (%d x %d x %d slots)\n", v.atlasTexels.x,
              v.atlasTexels.y, v.atlasTexels.z, v.atlasSlots.x, v.atlasSlots.y, v.atlasSlots.z);
  std::printf("  max hierarchy   %zu levels:", v.maxLevels.size());
  for (const auto& L : v.maxLevels) std::printf(" %dx%dx%d", L.dims.x, L.dims.y, L.dims.z);
  std::printf("\n  storage error   max |stored - float| = %.3g (max value %.3g)\n", v.stats.maxAbsError,
              v.stats.maxValue);
  std::printf("  memory          %.1f KiB total: atlas %.1f, indirection %.1f, majorants %.1f, "
              "ReSTIR's mean field %.1f KiB (path-traced renders leave it out); %.2f bytes per active voxel\n",
              m.totalBytes / 1024.0, m.atlasBytes / 1024.0, m.indirectionBytes / 1024.0,
              m.majorantBytes / 1024.0, m.coarseBytes / 1024.0, m.bytesPerActiveVoxel);
}

int runInfo(const InfoOptions& o) {
  for (const GridSummary& s : inspectVdb(o.file)) printSummary(s);
  if (!o.bake) return kExitOk;
  const LoadedGrid grid = loadFloatGrid(o.file, o.grid);
  if (grid.replacedValues)
    logWarn(strf("%s: grid \"%s\": %llu NaN/Inf/negative values replaced by 0", o.file.c_str(),
                 o.grid.c_str(), (unsigned long long)grid.replacedValues));
  for (TexelFormat f : {TexelFormat::Float16, TexelFormat::Float32}) {
    if (o.format != "both" && o.format != texelFormatName(f)) continue;
    BakeOptions opt;
    opt.format = f;
    std::vector<double> seconds;
    BakedVolume baked;
    for (int i = 0; i < std::max(1, o.repeat); ++i) {
      baked = bakeVolume(grid, opt);
      seconds.push_back(baked.stats.seconds);
    }
    std::sort(seconds.begin(), seconds.end());
    baked.stats.seconds = seconds[seconds.size() / 2];
    printBake(baked, int(seconds.size()));
  }
  return kExitOk;
}

}  // namespace

void addInfoCommand(CLI::App& app, Action& action) {
  auto opts = std::make_shared<InfoOptions>();
  CLI::App* cmd = app.add_subcommand("info", "Describe the grids of an OpenVDB file (and bake one)");
  cmd->add_option("file", opts->file, "OpenVDB file")->required();
  cmd->add_flag("--bake", opts->bake, "Bake a grid and report time, throughput and memory");
  cmd->add_option("--grid", opts->grid, "Grid to bake (default: density)");
  cmd->add_option("--format", opts->format, "Texel format to bake: float16, float32 or both")
      ->check(CLI::IsMember({"float16", "float32", "both"}));
  cmd->add_option("--repeat", opts->repeat, "Bakes per format; the median time is reported")
      ->check(CLI::Range(1, 1000));
  cmd->callback([opts, &action] { action = [opts] { return runInfo(*opts); }; });
}

}  // namespace plume
