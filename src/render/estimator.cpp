#include "render/estimator.h"

#include "core/error.h"
#include "core/log.h"

#include <vector>

namespace plume {

// Each in its own file (pt_estimator.cpp, restir_estimator.cpp).
EstimatorTraits pathTracerTraits();
std::unique_ptr<Estimator> makePathTracerEstimator(gpu::Context&, gpu::ShaderCompiler&, const Scene&,
                                                   const EstimatorOptions&);
EstimatorTraits restirTraits();
std::unique_ptr<Estimator> makeRestirEstimator(gpu::Context&, gpu::ShaderCompiler&, const Scene&, const EstimatorOptions&);
std::unique_ptr<Estimator> makeRestirBiasedEstimator(gpu::Context&, gpu::ShaderCompiler&, const Scene&,
                                                     const EstimatorOptions&);

namespace {

using Maker = std::unique_ptr<Estimator> (*)(gpu::Context&, gpu::ShaderCompiler&, const Scene&, const EstimatorOptions&);

struct Entry {
  EstimatorKind kind;
  const char* mode;  // render.mode
  EstimatorTraits traits;
  Maker make;
};

// The factory: one line per estimator (render.mode's choices in scene/settings.cpp list the modes).
const std::vector<Entry>& estimators() {
  static const std::vector<Entry> table = {
      {EstimatorKind::PathTracer, "pt", pathTracerTraits(), makePathTracerEstimator},
      {EstimatorKind::Restir, "restir", restirTraits(), makeRestirEstimator},
      {EstimatorKind::RestirBiased, "restir-biased", restirTraits(), makeRestirBiasedEstimator},
  };
  return table;
}

const Entry& entryOf(EstimatorKind kind) {
  for (const Entry& e : estimators()) {
    if (e.kind == kind) return e;
  }
  throw InternalError(strf("estimator kind %d has no entry in render/estimator.cpp", int(kind)));
}

}  // namespace

EstimatorKind estimatorKind(const RenderSettings& rs) {
  for (const Entry& e : estimators()) {
    if (rs.mode == e.mode) return e.kind;
  }
  throw InputError("render.mode: no estimator \"" + rs.mode + "\"");
}

const EstimatorTraits& estimatorTraits(EstimatorKind kind) { return entryOf(kind).traits; }

std::unique_ptr<Estimator> makeEstimator(EstimatorKind kind, gpu::Context& ctx, gpu::ShaderCompiler& compiler,
                                         const Scene& scene, const EstimatorOptions& options) {
  return entryOf(kind).make(ctx, compiler, scene, options);
}

std::string passTimesText(const PassTimes& times) {
  std::string s;
  for (const auto& [name, ms] : times) s += strf("%s%s %.2f ms", s.empty() ? "" : ", ", name.c_str(), ms);
  return s;
}

}  // namespace plume
