// Render settings, declared once: a table that gives every setting's JSON key (under "render"),
// command-line flag, default, valid range and help. The scene parser, the CLI and (later) the
// viewer and tests all read and write settings through this table.
#pragma once

#include <nlohmann/json_fwd.hpp>

#include <cstdint>
#include <string>
#include <variant>
#include <vector>

namespace plume {

struct RenderSettings {
  std::string mode = "pt";   // pt | restir | restir-biased
  int maxBounces = 8;        // largest number of scattering events on a path (1 = single)
  int spp = 4;               // samples per pixel per frame
  int64_t seed = 1;          // 0 .. 2^32-1
  int frameFirst = 1;        // render.frames = [first, last]
  int frameLast = 1;
  int rrStartBounce = 3;     // Russian roulette from this bounce on (unbiased)
  // How the GPU estimators interpolate the density and emission grids: "exact" (8 texel reads,
  // exact weights: the field the CPU reference tracks), "biased-hardware" (the texture unit's
  // trilinear filter: fewer instructions, weights rounded to the device's sub-texel precision) or
  // "auto": the filter where its weights are measured exact on the device (render/filter_probe.h).
  std::string densityFilter = "auto";
  // Volumetric ReSTIR (DESIGN §4.2; src/render/restir.h)
  int restirCandidates = 4;          // M: candidate paths per pixel and frame
  int restirCandidatesMoving = 0;    // ... in frames whose camera moved (0: restirCandidates)
  int restirNeighbours = 2;          // k: spatial neighbours per round (2 beat 3 at equal time
                                     // everywhere measured: notes/restir.md "Session 24")
  int restirRadius = 16;             // spatial neighbour radius, pixels
  int restirRounds = 1;              // R: spatial rounds (0 = no spatial reuse)
  int restirRoundsStatic = -1;       // ... where camera and grid are both still (-1: restirRounds)
  int restirHistoryCap = 20;         // temporal confidence cap c: M_hist <= c * M_cur (0 = no temporal)
  int restirHistoryCapMoving = 8;    // ... while the camera moves (at most restirHistoryCap)
  int restirHistoryCapStatic = 0;    // ... where camera and grid are both still (0: restirHistoryCap)
  std::string restirMis = "pairwise";  // pairwise | gbh (generalised balance heuristic)
  int restirPrefix = 16;             // path vertices a reservoir holds; longer paths: a path-traced tail
  int restirLightCandidates = 2;     // light samples resampled at each candidate vertex (RIS)
  int restirLightCandidatesMoving = 0;  // ... in frames whose camera moved (0: restirLightCandidates)
  std::string restirShift = "reconnect";  // reconnect (at the first surface vertex after the primary) | copy
  std::string restirTarget = "colour";    // colour (each pixel's channels weighed by its colour) | luminance
  std::string restirEmissionReservoir = "own";  // own (an emitting medium's emission paths resampled apart) | shared
};

struct SettingDesc {
  using Member = std::variant<int RenderSettings::*, int64_t RenderSettings::*,
                              std::string RenderSettings::*>;
  const char* key;    // JSON key under "render" and CLI flag (--key, '_' -> '-')
  const char* help;
  Member member;
  double min = 0, max = 0;              // numeric range (inclusive)
  std::vector<std::string> choices;     // for strings; empty = any
};

const std::vector<SettingDesc>& renderSettingsTable();

// Sets `key` from a JSON value; throws InputError "<where>: <keyPath>: ..." on a bad value.
// "frames" takes [first, last] (or a single number). Returns false for an unknown key.
bool applyRenderSetting(RenderSettings& s, const std::string& key, const nlohmann::json& value,
                        const std::string& where, const std::string& keyPath);
// Same, from command-line text ("16", "restir", "1-48" for frames).
bool applyRenderSettingText(RenderSettings& s, const std::string& key, const std::string& text);

std::string cliFlagFor(const std::string& key);  // "max_bounces" -> "--max-bounces"

}  // namespace plume
