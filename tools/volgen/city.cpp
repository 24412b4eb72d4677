// `plume-volgen city`: the many-lights scene's geometry (issue 12; volumes/README.md "city/"), a
// night city around the bundled smoke's source, as Wavefront OBJ files written by hand:
//   city_buildings.obj     boxes (four walls and a roof, no floor), diffuse in city.json;
//   city_lamps.obj         street lamps: small quads facing down, over the streets;
//   city_windows_warm.obj  lit windows: small quads just in front of the walls, facing out;
//   city_windows_cool.obj  the same with the cool light (a share of the windows).
// Exactly `quads` emissive quads in all (a `lampShare` of them street lamps, the rest windows),
// chosen among every street-lamp and window slot by a hash of the seed, so the same arguments write
// the same bytes. Layout: a square street grid of pitch `block` with streets `street` wide; each
// lot whose centre lies between `plaza` and `radius` from the origin holds one box (or none: a
// park), taller towards the plaza; the plaza around the smoke's source stays open. Faces are
// counter-clockwise seen from their front (DESIGN §2), so walls and windows face out, lamps down.
#include "volgen.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace volgen {
namespace {

constexpr float kFloorPitch = 0.034f;      // storey height, world units
constexpr float kWindowPitch = 0.028f;     // window columns along a wall
constexpr float kWindowSize[2] = {0.013f, 0.017f};  // width, height
constexpr float kWindowGap = 0.0015f;      // windows stand this far in front of their wall
constexpr float kLampPitch = 0.2f;         // street lamps along a street, alternating sides
constexpr float kLampHeight = 0.05f;
constexpr float kLampSize = 0.012f;
constexpr float kParkShare = 0.08f;        // lots left empty

struct Quad {
  float c[4][3];  // corners, counter-clockwise seen from the front
};

// A slot for an emissive quad; `key` orders the choice (smallest first), `cool` picks the colour.
struct Slot {
  Quad q;
  float key;
  bool cool;
};

// The axis-aligned quad centred at `c` in the plane normal to axis `n` (0 = x, 2 = z, 1 = y) on
// the side `sign`, `w` wide and `h` tall (for y: w along x, h along z), facing n * sign.
Quad axisQuad(const float c[3], int n, float sign, float w, float h) {
  Quad q{};
  // Tangents (u, v) with cross(u, v) = the front normal.
  float u[3] = {0, 0, 0}, v[3] = {0, 0, 0};
  if (n == 1) {
    u[0] = 1.0f, v[2] = -sign;  // cross(x, -sign z) = sign y
  } else {
    v[1] = 1.0f;  // up
    if (n == 0) u[2] = -sign;  // cross(-sign z, y) = sign x
    else u[0] = sign;          // cross(sign x, y) = sign z
  }
  const float su[4] = {-0.5f, 0.5f, 0.5f, -0.5f}, sv[4] = {-0.5f, -0.5f, 0.5f, 0.5f};
  for (int k = 0; k < 4; ++k)
    for (int i = 0; i < 3; ++i) q.c[k][i] = c[i] + su[k] * w * u[i] + sv[k] * h * v[i];
  return q;
}

struct ObjWriter {
  FILE* f = nullptr;
  std::string path;
  int vertices = 0, faces = 0;

  ObjWriter(const std::string& p, const std::string& header) : path(p) {
    f = std::fopen(p.c_str(), "w");
    if (!f) throw std::runtime_error("cannot write " + p);
    std::fprintf(f, "%s", header.c_str());
  }
  ObjWriter(const ObjWriter&) = delete;
  ~ObjWriter() {
    if (f) std::fclose(f);
  }
  void quad(const Quad& q) {
    for (const auto& c : q.c) std::fprintf(f, "v %.4f %.4f %.4f\n", c[0], c[1], c[2]);
    std::fprintf(f, "f %d %d %d %d\n", vertices + 1, vertices + 2, vertices + 3, vertices + 4);
    vertices += 4;
    ++faces;
  }
  // A box on the ground (y = 0): four walls and a roof, facing out.
  void box(float x0, float x1, float z0, float z1, float h) {
    const int b = vertices;
    const float xs[2] = {x0, x1}, zs[2] = {z0, z1};
    for (int y = 0; y < 2; ++y)
      for (int k = 0; k < 4; ++k) {  // corners counter-clockwise seen from above
        const int ix = (k == 1 || k == 2), iz = (k >= 2) ? 0 : 1;
        std::fprintf(f, "v %.4f %.4f %.4f\n", xs[ix], y ? h : 0.0f, zs[iz]);
      }
    vertices += 8;
    // Bottom ring b+1..b+4, top ring b+5..b+8: (x0,z1) (x1,z1) (x1,z0) (x0,z0).
    for (int k = 0; k < 4; ++k) {
      const int a = b + 1 + k, c = b + 1 + (k + 1) % 4;
      std::fprintf(f, "f %d %d %d %d\n", a, c, c + 4, a + 4);
    }
    std::fprintf(f, "f %d %d %d %d\n", b + 5, b + 6, b + 7, b + 8);
    faces += 5;
  }
  void close() {
    const bool ok = std::ferror(f) == 0;
    const int rc = std::fclose(f);
    f = nullptr;
    if (rc != 0 || !ok) throw std::runtime_error("cannot write " + path);
  }
};

void checkParams(const CityParams& p) {
  auto bad = [](const std::string& what) { throw std::runtime_error("city: " + what); };
  if (p.quads < 1) bad("--quads must be at least 1");
  if (!(p.lampShare >= 0.0 && p.lampShare <= 1.0)) bad("--lamp-share must be in [0, 1]");
  if (!(p.coolShare >= 0.0 && p.coolShare <= 1.0)) bad("--cool-share must be in [0, 1]");
  if (!(p.block > 0.1 && p.block <= 10.0)) bad("--block must be in (0.1, 10] world units");
  if (!(p.street > 0.06 && p.street < 0.5 * p.block)) bad("--street must be above 0.06 and below half of --block");
  if (!(p.plaza >= 0.0)) bad("--plaza must be >= 0");
  if (!(p.radius > p.plaza + p.block && p.radius <= 100.0)) bad("--radius must exceed --plaza + --block and be <= 100");
  if (!(p.maxHeight > kFloorPitch && p.maxHeight <= 100.0)) bad("--max-height must be in (0.034, 100]");
}

struct Box {
  float x0, z0, wx, wz;  // a corner and the footprint's size
  int storeys;
};

struct City {
  std::vector<Box> boxes;
  std::vector<Slot> windows, lamps;  // every slot; the chosen ones after keepSmallest
};

// The window slots on a box's four walls, one per storey and column, facing out. A building's own
// share of lit windows varies (`litBias` scales its keys), and its light is warm or cool.
void addWindows(City& city, const Box& b, uint32_t seed, uint32_t lot, double coolShare) {
  const float litBias = hashUnit(seed, lot, 7);
  const bool coolBuilding = hashUnit(seed, lot, 8) < coolShare;
  const float wx = b.wx, wz = b.wz;
  uint32_t slot = 0;
  for (int wall = 0; wall < 4; ++wall) {
    const int n = wall < 2 ? 0 : 2;  // walls facing x, then z
    const float sign = (wall % 2) ? 1.0f : -1.0f;
    const float len = n == 0 ? wz : wx;
    const int cols = int((len - 0.008f) / kWindowPitch);
    const float start = (n == 0 ? b.z0 : b.x0) + 0.5f * (len - float(cols - 1) * kWindowPitch);
    for (int s = 0; s < b.storeys; ++s) {
      for (int col = 0; col < cols; ++col, ++slot) {
        float c[3];
        c[1] = (float(s) + 0.55f) * kFloorPitch;
        const float along = start + float(col) * kWindowPitch;
        if (n == 0) {
          c[0] = (sign > 0 ? b.x0 + wx : b.x0) + sign * kWindowGap;
          c[2] = along;
        } else {
          c[0] = along;
          c[2] = (sign > 0 ? b.z0 + wz : b.z0) + sign * kWindowGap;
        }
        const float key = hashUnit(seed, lot, 100 + slot) * (0.3f + 0.7f * litBias);
        city.windows.push_back({axisQuad(c, n, sign, kWindowSize[0], kWindowSize[1]), key, coolBuilding});
      }
    }
  }
}

// Lots: cell (i, k) spans [i, i+1] x [k, k+1] blocks and streets run along the cell edges; a lot
// whose centre lies between the plaza and the radius holds one box (or is a park).
void addBuildings(City& city, const CityParams& p, int cells) {
  const float half = 0.5f * float(p.street);
  for (int i = -cells; i < cells; ++i) {
    for (int k = -cells; k < cells; ++k) {
      const float cx = (float(i) + 0.5f) * float(p.block), cz = (float(k) + 0.5f) * float(p.block);
      const float r = std::hypot(cx, cz);
      if (r < p.plaza + 0.5 * p.block || r > p.radius) continue;
      const uint32_t lot = uint32_t(i + 1000) * 4096u + uint32_t(k + 1000);
      if (hashUnit(p.seed, lot, 1) < kParkShare) continue;
      // The footprint: 60-100% of the lot on each axis, placed anywhere in it.
      const float lotW = float(p.block) - float(p.street);
      const float wx = lotW * (0.6f + 0.4f * hashUnit(p.seed, lot, 2)), wz = lotW * (0.6f + 0.4f * hashUnit(p.seed, lot, 3));
      const float x0 = float(i) * float(p.block) + half + (lotW - wx) * hashUnit(p.seed, lot, 4);
      const float z0 = float(k) * float(p.block) + half + (lotW - wz) * hashUnit(p.seed, lot, 5);
      // Taller near the plaza: up to maxHeight there, a third of it at the rim; storeys whole.
      const float fall = std::exp(-(r - float(p.plaza)) / (0.6f * float(p.radius - p.plaza)));
      const float u = hashUnit(p.seed, lot, 6);
      const float hMax = float(p.maxHeight) * (0.3f + 0.7f * fall);
      const int storeys = std::max(1, int(hMax * (0.25f + 0.75f * u * u) / kFloorPitch));
      city.boxes.push_back({x0, z0, wx, wz, storeys});
      addWindows(city, city.boxes.back(), p.seed, lot, p.coolShare);
    }
  }
}

// Street lamps: along every street line within the radius, every kLampPitch, alternating sides.
void addLamps(City& city, const CityParams& p, int cells) {
  const float half = 0.5f * float(p.street);
  for (int axis = 0; axis < 2; ++axis) {
    for (int line = -cells; line <= cells; ++line) {
      const float across = float(line) * float(p.block);
      const int steps = int(p.radius / kLampPitch);
      for (int j = -steps; j <= steps; ++j) {
        const float along = float(j) * kLampPitch;
        const float side = (j % 2 == 0 ? 1.0f : -1.0f) * (half - 0.015f);
        float c[3] = {0.0f, kLampHeight, 0.0f};
        c[axis == 0 ? 0 : 2] = along;
        c[axis == 0 ? 2 : 0] = across + side;
        if (std::hypot(c[0], c[2]) > p.radius) continue;
        const uint32_t id = uint32_t(axis) * 1000000u + uint32_t(line + 1000) * 1000u + uint32_t(j + 500);
        city.lamps.push_back({axisQuad(c, 1, -1.0f, kLampSize, kLampSize), hashUnit(p.seed, id, 9), false});
      }
    }
  }
}

// Keeps the n slots of smallest key (ties by position in the list), in their original order.
void keepSmallest(std::vector<Slot>& slots, int n) {
  std::vector<size_t> order(slots.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return slots[a].key < slots[b].key; });
  std::vector<bool> keep(slots.size(), false);
  for (int i = 0; i < n; ++i) keep[order[size_t(i)]] = true;
  std::vector<Slot> out;
  for (size_t i = 0; i < slots.size(); ++i)
    if (keep[i]) out.push_back(slots[i]);
  slots.swap(out);
}

}  // namespace

int runCity(const CityParams& p) {
  checkParams(p);
  City city;
  const int cells = int(std::ceil(p.radius / p.block)) + 1;
  addBuildings(city, p, cells);
  addLamps(city, p, cells);
  const int nLamps = int(std::lround(double(p.quads) * p.lampShare));
  const int nWindows = p.quads - nLamps;
  const size_t lampSlots = city.lamps.size(), windowSlots = city.windows.size();
  if (size_t(nLamps) > lampSlots)
    throw std::runtime_error("city: " + std::to_string(nLamps) + " street lamps asked for, but the streets hold " +
                             std::to_string(lampSlots) + "; lower --quads or --lamp-share, or raise --radius");
  if (size_t(nWindows) > windowSlots)
    throw std::runtime_error("city: " + std::to_string(nWindows) + " lit windows asked for, but the buildings have " +
                             std::to_string(windowSlots) + "; lower --quads or raise --lamp-share or --radius");
  keepSmallest(city.lamps, nLamps);
  keepSmallest(city.windows, nWindows);

  const std::filesystem::path dir(p.out);
  std::filesystem::create_directories(dir);
  char header[512];
  std::snprintf(header, sizeof header,
                "# plume-volgen city --quads %d --seed %u --radius %g --plaza %g --block %g --street %g "
                "--max-height %g --lamp-share %g --cool-share %g\n",
                p.quads, p.seed, p.radius, p.plaza, p.block, p.street, p.maxHeight, p.lampShare, p.coolShare);
  ObjWriter bw((dir / "city_buildings.obj").string(), std::string(header) + "o buildings\n");
  for (const Box& b : city.boxes) bw.box(b.x0, b.x0 + b.wx, b.z0, b.z0 + b.wz, float(b.storeys) * kFloorPitch);
  bw.close();
  ObjWriter lw((dir / "city_lamps.obj").string(), std::string(header) + "o lamps\n");
  for (const Slot& s : city.lamps) lw.quad(s.q);
  lw.close();
  ObjWriter ww((dir / "city_windows_warm.obj").string(), std::string(header) + "o windows_warm\n");
  ObjWriter wc((dir / "city_windows_cool.obj").string(), std::string(header) + "o windows_cool\n");
  for (const Slot& s : city.windows) (s.cool ? wc : ww).quad(s.q);
  ww.close();
  wc.close();
  std::printf("%s: %zu buildings (%d quads); %s: %d lamps (of %zu slots); %s: %d windows; %s: %d windows (of %zu "
              "slots); %d emissive quads\n",
              bw.path.c_str(), city.boxes.size(), bw.faces, lw.path.c_str(), lw.faces, lampSlots, ww.path.c_str(),
              ww.faces, wc.path.c_str(), wc.faces, windowSlots, lw.faces + ww.faces + wc.faces);
  return 0;
}

}  // namespace volgen
