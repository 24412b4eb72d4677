// `plume compare a.exr b.exr [--alpha 0.01] [--exact-b]`
//
// Compares two renders of the same scene (DESIGN §6, §7 tier d). Prints relMSE of a against b
// (b is the reference), the mean ratio mean(a)/mean(b), and a per-pixel Z-test
// z = (a - b) / sqrt(var_a + var_b) per channel with a Šidák correction over all 3·W·H channel
// tests at family-wise level alpha: the failing-pixel fraction and the worst pixel.
//
// Exit codes: 0 the Z-test passes, 1 it fails, 2 bad input: a missing or unreadable file,
// different sizes, alpha outside (0, 1), or missing variance channels (var.R, var.G, var.B).
// Without variances the Z-test cannot run: relMSE and the mean ratio are still printed, then
// an error says so and the exit code is 2 (a comparison that was not made must not pass).
// --exact-b treats b as exact (an analytic image): only a's variance is used and b needs none.
// --worst N lists the N pixels holding the largest shares of relMSE (with both images' values)
// and the share held by the worst 1% of the pixels: where the error sits.
#include "app/commands.h"
#include "core/error.h"
#include "core/log.h"
#include "core/stats.h"
#include "io/image.h"

#include <cstdio>
#include <memory>

namespace plume {
namespace {

struct CompareOptions {
  std::string a, b;
  double alpha = kZTestAlpha;
  bool exactB = false;
  int worst = 0;
};

void printWorst(const Image& a, const Image& b, int n) {
  if (n <= 0) return;
  std::printf("worst 1%% of pixels hold %.1f%% of relMSE; the largest shares:\n",
              100.0 * shareOfWorst(a, b, 0.01));
  for (const PixelError& e : worstPixels(a, b, n)) {
    const size_t i = 3 * (size_t(e.y) * size_t(a.width) + size_t(e.x));
    std::printf("  (%d, %d) %5.1f%%  a (%.4g, %.4g, %.4g)  b (%.4g, %.4g, %.4g)\n", e.x, e.y,
                100.0 * e.share, a.rgb[i], a.rgb[i + 1], a.rgb[i + 2], b.rgb[i], b.rgb[i + 1], b.rgb[i + 2]);
  }
}

int runCompare(const CompareOptions& o) {
  if (o.worst < 0) throw InputError(strf("--worst %d: must be 0 or more", o.worst));
  if (!(o.alpha > 0.0 && o.alpha < 1.0)) {
    throw InputError(strf("--alpha %g: must lie strictly between 0 and 1", o.alpha));
  }
  const Image a = readExr(o.a);
  const Image b = readExr(o.b);
  if (a.width != b.width || a.height != b.height) {
    throw InputError(strf("%s is %dx%d but %s is %dx%d", o.a.c_str(), a.width, a.height,
                          o.b.c_str(), b.width, b.height));
  }
  const bool missingVariance = !a.hasVariance() || (!o.exactB && !b.hasVariance());
  if (missingVariance) {
    std::printf("relMSE       %.6g\nmean ratio   %.6g\n", relMse(a, b), meanRatio(a.rgb, b.rgb));
    printWorst(a, b, o.worst);
    const std::string& which = !a.hasVariance() ? o.a : o.b;
    throw InputError(strf("%s has no variance channels (var.R, var.G, var.B): the Z-test "
                          "cannot run", which.c_str()));
  }
  const ZTestResult r = o.exactB ? zTestAgainst(a, b.rgb, o.alpha) : zTest(a, b, o.alpha);
  std::printf("%s", r.summary().c_str());
  printWorst(a, b, o.worst);
  return r.pass ? kExitOk : kExitTestFailed;
}

}  // namespace

void addCompareCommand(CLI::App& app, Action& action) {
  auto options = std::make_shared<CompareOptions>();
  CLI::App* cmd = app.add_subcommand(
      "compare", "Per-pixel Z-test, relMSE and mean ratio of a.exr against the reference b.exr "
                 "(exit 0 pass, 1 fail, 2 bad input)");
  cmd->add_option("a", options->a, "EXR to judge (needs var.R, var.G, var.B)")->required();
  cmd->add_option("b", options->b, "reference EXR (needs variance unless --exact-b)")->required();
  cmd->add_option("--alpha", options->alpha, "family-wise significance level")
      ->capture_default_str();
  cmd->add_flag("--exact-b", options->exactB, "treat b as exact: use only a's variance");
  cmd->add_option("--worst", options->worst,
                  "also list the N pixels holding the largest shares of relMSE");
  cmd->callback([options, &action] { action = [options] { return runCompare(*options); }; });
}

}  // namespace plume
