// The bench's outputs (`plume bench`): a markdown table (also kept in BenchResult::markdown),
// a CSV and an SVG plot of relMSE against GPU time per frame (log-log, the path tracer's curve
// as a line), written as <dir>/<scene stem>_bench.{md,csv,svg}.
#pragma once

#include "bench/bench.h"

#include <string>

namespace plume {

// Fills result.markdown and the paths; `first` is the frame whose grid was held still.
void writeBenchReport(BenchResult& result, const Scene& scene, const BenchOptions& o, int first, const std::string& dir);

}  // namespace plume
