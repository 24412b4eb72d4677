#include "scene/settings.h"

#include "core/error.h"
#include "core/log.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <limits>

namespace plume {

const std::vector<SettingDesc>& renderSettingsTable() {
  static const std::vector<SettingDesc> table = {
      {"mode", "estimator: pt (delta-tracking path tracer), restir (unbiased), restir-biased",
       &RenderSettings::mode, 0, 0, {"pt", "restir", "restir-biased"}},
      {"max_bounces", "largest number of scattering events on a path (1 = single scattering)",
       &RenderSettings::maxBounces, 0, 100000, {}},
      {"spp", "samples per pixel per frame", &RenderSettings::spp, 1, 1 << 24, {}},
      {"seed", "random seed (0 .. 2^32-1); same seed and device give the same image",
       &RenderSettings::seed, 0, 4294967295.0, {}},
      {"rr_start_bounce", "first bounce at which Russian roulette may end a path",
       &RenderSettings::rrStartBounce, 1, 100000, {}},
      {"density_filter",
       "GPU density and emission lookups: auto (the texture unit's trilinear filter where this device's "
       "filter is measured exact, weights within 2^-16 as on lavapipe; 8 texel reads elsewhere), exact (8 texel "
       "reads, the CPU reference's field) or biased-hardware (the texture unit's filter on any device: faster, "
       "biased by the device's rounding of the weights, 8 bits on most GPUs; README \"The scene file\")",
       &RenderSettings::densityFilter, 0, 0, {"auto", "exact", "biased-hardware"}},
      {"restir_candidates", "ReSTIR: candidate paths M per pixel and frame", &RenderSettings::restirCandidates, 1, 64, {}},
      {"restir_candidates_moving",
       "ReSTIR: candidate paths per pixel in frames whose camera moved (0 = restir_candidates). A moving "
       "camera's history is shifted into the new pixels and where shifts fail the pixel's own candidates "
       "carry it: more of them lower a moving frame's error, on the bundled city about as much as they "
       "cost in time (notes/city.md \"Session 18\")",
       &RenderSettings::restirCandidatesMoving, 0, 64, {}},
      {"restir_neighbours", "ReSTIR: spatial neighbours k per round", &RenderSettings::restirNeighbours, 1, 8, {}},
      {"restir_radius", "ReSTIR: spatial neighbour radius in pixels", &RenderSettings::restirRadius, 1, 256, {}},
      {"restir_rounds", "ReSTIR: spatial reuse rounds R (0 = no spatial reuse)", &RenderSettings::restirRounds, 0, 8, {}},
      {"restir_rounds_static",
       "ReSTIR: spatial reuse rounds in frames where neither the camera nor the grid changed since the previous "
       "frame (-1 = restir_rounds): 0 goes with a long restir_history_cap_static (see there), spatial reuse "
       "staying in the frames whose history a shift thins out",
       &RenderSettings::restirRoundsStatic, -1, 8, {}},
      {"restir_history_cap", "ReSTIR: temporal confidence cap c, M_hist <= c * M_cur (0 = no temporal reuse)",
       &RenderSettings::restirHistoryCap, 0, 1000, {}},
      {"restir_history_cap_moving",
       "ReSTIR: the temporal confidence cap while the camera moves (the smaller of it and restir_history_cap "
       "applies; 0 = no temporal reuse while it moves). A moving camera's history is shifted into the new "
       "pixels, and pairwise MIS lets a history sample whose target grows by a factor r under the shift weigh "
       "up to about min(r, cap) times its usual weight: a long history turns the samples the shift brightens "
       "most into lasting fireflies. 8 measured best over smoke (notes/restir.md \"Session 29\"); where many "
       "shifts fail (surfaces, small lamps) a shorter one is (the bundled city sets 5)",
       &RenderSettings::restirHistoryCapMoving, 0, 1000, {}},
      {"restir_history_cap_static",
       "ReSTIR: the temporal confidence cap in frames where neither the camera nor the grid changed since the "
       "previous frame (a paused viewer, a still shot of one grid frame; 0 = restir_history_cap; none with "
       "restir_history_cap 0, which turns temporal reuse off). The history's "
       "path then lands where it was and both targets are one function, so the history is the pixel's own "
       "earlier candidates and no sample's weight grows under the shift: the longer the cap, the more of them "
       "a still view keeps resampling. With spatial reuse in those frames (restir_rounds_static) a long history "
       "grows fireflies instead: neighbours' histories reach a pixel shifted, and the samples a shift brightens "
       "weigh up to the cap times their due; hence restir_rounds_static 0 with it. For frames shown one at a "
       "time, each from its own history (the bench's metric; the bundled city with 400: 39-54x lower relMSE "
       "than the path tracer at equal time per frame, 12-14x with its own settings): where frames are averaged "
       "(plume render's iterations, the viewer's accumulation) their correlation costs more than the cap gains, "
       "so no bundled scene sets it (notes/city.md \"Session 32\")",
       &RenderSettings::restirHistoryCapStatic, 0, 100000, {}},
      {"restir_mis", "ReSTIR: MIS weights for reuse: pairwise (O(k)) or gbh (generalised balance heuristic, O(k^2))",
       &RenderSettings::restirMis, 0, 0, {"pairwise", "gbh"}},
      {"restir_light_candidates",
       "ReSTIR: light samples drawn at each candidate vertex and resampled by their unshadowed contribution; "
       "with more than 1 only the survivor takes a shadow ray (1 = one light sample, shadowed; used with "
       "emissive surfaces only)",
       &RenderSettings::restirLightCandidates, 1, 64, {}},
      {"restir_light_candidates_moving",
       "ReSTIR: light samples resampled at each candidate vertex in frames whose camera moved (0 = "
       "restir_light_candidates; emissive surfaces only). A moving camera's reservoirs hold few frames of "
       "history, so a better light choice per candidate pays there sooner than with a still one (the bundled "
       "city: 4 while moving, with 3 candidates, notes/city.md \"Session 37\")",
       &RenderSettings::restirLightCandidatesMoving, 0, 64, {}},
      {"restir_shift",
       "ReSTIR: how reuse moves a path into another pixel where it meets surfaces: reconnect (the first surface "
       "vertex after the primary one is kept in place and the shifted path connects to it) or copy (every "
       "direction is copied; each surface vertex is wherever the copied ray lands). Both unbiased; scenes "
       "without surfaces are unaffected",
       &RenderSettings::restirShift, 0, 0, {"reconnect", "copy"}},
      {"restir_target",
       "ReSTIR: the scalar its resampling weighs a path's RGB contribution by: colour (each channel divided by "
       "the pixel's own colour as the earlier frames estimated it, so that a pixel's rare paths of another "
       "colour, a fire's sky light, a street's cold lamp, weigh by their share of that channel) or luminance "
       "(the channels' mean). Both unbiased (notes/restir.md \"Session 39\")",
       &RenderSettings::restirTarget, 0, 0, {"colour", "luminance"}},
      {"restir_emission_reservoir",
       "ReSTIR with an emitting medium and lights: own (the paths that end in the medium's emission are "
       "resampled and reused in a reservoir of their own, beside the one of the paths that end at a light; "
       "final shading adds the two) or shared (one reservoir for both). A pixel shades one path per "
       "reservoir, and with one reservoir that path is the fire's orange or the sky's blue, a colour noise "
       "no number of candidates removes: on the bundled fire own halves the error per frame for a third "
       "more time (notes/restir.md \"Session 40\"). Both unbiased; other scenes are unaffected",
       &RenderSettings::restirEmissionReservoir, 0, 0, {"own", "shared"}},
      {"restir_prefix",
       "ReSTIR: scattering vertices a reservoir's path holds (1-16, shared::RS_MAX_VERTICES); paths with more "
       "(up to max_bounces) are path traced in final shading",
       &RenderSettings::restirPrefix, 1, 16, {}},
  };
  return table;
}

std::string cliFlagFor(const std::string& key) {
  std::string flag = "--" + key;
  for (char& c : flag) c = c == '_' ? '-' : c;
  return flag;
}

namespace {

[[noreturn]] void bad(const std::string& where, const std::string& keyPath, const std::string& what) {
  throw InputError(where + ": " + keyPath + ": " + what);
}

int64_t integerIn(const nlohmann::json& v, double lo, double hi, const std::string& where,
                  const std::string& keyPath) {
  auto rangeText = [&] { return strf("expected an integer in [%.0f, %.0f]", lo, hi); };
  if (!v.is_number()) bad(where, keyPath, rangeText());
  double d = v.get<double>();
  if (!std::isfinite(d) || d != std::floor(d) || d < lo || d > hi) bad(where, keyPath, rangeText());
  return int64_t(d);
}

}  // namespace

bool applyRenderSetting(RenderSettings& s, const std::string& key, const nlohmann::json& value,
                        const std::string& where, const std::string& keyPath) {
  if (key == "frames") {
    const double lim = 1e7;
    if (value.is_number()) {
      s.frameFirst = s.frameLast = int(integerIn(value, -lim, lim, where, keyPath));
    } else if (value.is_array() && value.size() == 2) {
      int a = int(integerIn(value[0], -lim, lim, where, keyPath));
      int b = int(integerIn(value[1], -lim, lim, where, keyPath));
      if (b < a) bad(where, keyPath, "expected [first, last] with first <= last");
      s.frameFirst = a;
      s.frameLast = b;
    } else {
      bad(where, keyPath, "expected [first, last] frame numbers");
    }
    return true;
  }
  for (const SettingDesc& d : renderSettingsTable()) {
    if (key != d.key) continue;
    if (auto* m = std::get_if<int RenderSettings::*>(&d.member)) {
      s.*(*m) = int(integerIn(value, d.min, d.max, where, keyPath));
    } else if (auto* m64 = std::get_if<int64_t RenderSettings::*>(&d.member)) {
      s.*(*m64) = integerIn(value, d.min, d.max, where, keyPath);
    } else if (auto* ms = std::get_if<std::string RenderSettings::*>(&d.member)) {
      if (!value.is_string()) bad(where, keyPath, "expected a string");
      std::string text = value.get<std::string>();
      if (!d.choices.empty()) {
        bool ok = false;
        std::string list;
        for (const auto& c : d.choices) {
          ok = ok || c == text;
          list += (list.empty() ? "" : ", ") + c;
        }
        if (!ok) bad(where, keyPath, "expected one of " + list + " (got \"" + text + "\")");
      }
      s.*(*ms) = text;
    }
    return true;
  }
  return false;
}

bool applyRenderSettingText(RenderSettings& s, const std::string& key, const std::string& text) {
  nlohmann::json value;
  if (key == "frames") {
    auto dash = text.find('-', 1);
    try {
      if (dash == std::string::npos) {
        value = std::stoll(text);
      } else {
        value = nlohmann::json::array({std::stoll(text.substr(0, dash)), std::stoll(text.substr(dash + 1))});
      }
    } catch (const std::exception&) {
      throw InputError("command line: --frames: expected FIRST-LAST or a frame number (got \"" + text + "\")");
    }
  } else {
    value = nlohmann::json::parse(text, nullptr, false);
    if (value.is_discarded() || value.is_object() || value.is_array()) value = text;  // plain string
  }
  return applyRenderSetting(s, key, value, "command line", cliFlagFor(key));
}

}  // namespace plume
