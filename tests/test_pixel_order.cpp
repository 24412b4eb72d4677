// render/pixel_order.h: the pixels whose camera rays may meet a volume's footprint (its box, or its
// occupied cells) (ReSTIR runs walk-free
// variants of its passes over the others, so a pixel left out wrongly would lose its light). CPU
// only: random cameras and boxes (rotated, scaled, moved), random sub-pixel rays intersected with
// the box in double precision; every pixel with a hit must be in the list's inside part, and
// every inside pixel must be near a hit (the margins are a pixel and a twentieth of a voxel),
// unless the box reaches the camera's plane (then every pixel is inside).
#include "render/gpu_scene.h"
#include "render/pixel_order.h"
#include "scene/scene.h"

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <tuple>

using namespace plume;

namespace {

shared::GpuCamera cameraAt(glm::vec3 position, glm::vec3 lookAt, float fovY, int width, int height) {
  Camera c;
  c.base.position = position;
  c.base.lookAt = lookAt;
  c.base.fovY = fovY;
  c.width = width;
  c.height = height;
  return gpuCamera(c, 0);
}

// The ray through image point (px, py) meets the index-space box [lo, hi] (slab test, double).
bool rayMeetsBox(const shared::GpuCamera& cam, int width, int height, double px, double py, glm::dvec3 lo,
                 glm::dvec3 hi, const glm::dmat4& worldToIndex) {
  const double sx = (2.0 * px / width - 1.0) * cam.tanHalfFovY * cam.aspect;
  const double sy = (1.0 - 2.0 * py / height) * cam.tanHalfFovY;
  const glm::dvec3 dir = glm::dvec3(cam.forward) + sx * glm::dvec3(cam.right) + sy * glm::dvec3(cam.up);
  const glm::dvec3 o = glm::dvec3(worldToIndex * glm::dvec4(glm::dvec3(cam.position), 1.0));
  const glm::dvec3 d = glm::dvec3(worldToIndex * glm::dvec4(dir, 0.0));
  double t0 = 0.0, t1 = 1e300;
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0) {
      if (o[a] < lo[a] || o[a] > hi[a]) return false;
      continue;
    }
    double ta = (lo[a] - o[a]) / d[a], tb = (hi[a] - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return t0 < t1;
}

VolumeFootprint footprintOf(glm::vec3 lo, glm::vec3 hi, const glm::mat4& indexToWorld, bool empty = false,
                            std::vector<IndexBox> cells = {}) {
  VolumeFootprint v;
  v.bounds = {lo, hi};
  v.indexToWorld = indexToWorld;
  v.empty = empty;
  v.cells = std::move(cells);
  return v;
}

struct Split {
  size_t inside = 0, hits = 0, missed = 0, far = 0;
};

// The footprint's boxes: the occupied cells, or the bounds where there are none.
Split check(const shared::GpuCamera& cam, int width, int height, const VolumeFootprint& v, std::mt19937& rng) {
  const PixelOrder order = volumePixelOrder(cam, width, height, v);
  std::vector<IndexBox> boxes = v.cells;
  if (boxes.empty()) boxes.push_back(v.bounds);
  EXPECT_EQ(order.pixels.size(), size_t(width) * height);
  std::vector<char> in(size_t(width) * height, 0);
  for (uint32_t i = 0; i < order.pixels.size(); ++i) {
    const uint32_t x = order.pixels[i] & 0xffffu, y = order.pixels[i] >> 16;
    EXPECT_EQ(in[y * width + x], 0) << "pixel listed twice";
    in[y * width + x] = i < order.inside ? 1 : 2;
  }
  const glm::dmat4 worldToIndex = glm::inverse(glm::dmat4(v.indexToWorld));
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<char> hit(in.size(), 0);
  Split s;
  s.inside = order.inside;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      bool any = false;
      for (int k = 0; k < 24 && !any; ++k) {
        const double fx = k < 4 ? (k & 1) : k == 4 ? 0.5 : u(rng), fy = k < 4 ? (k >> 1) : k == 4 ? 0.5 : u(rng);
        for (const IndexBox& b : boxes) {
          any = any || rayMeetsBox(cam, width, height, x + fx, y + fy, glm::dvec3(b.lo), glm::dvec3(b.hi), worldToIndex);
        }
      }
      hit[size_t(y) * width + x] = any ? 1 : 0;
      s.hits += any ? 1 : 0;
      if (any && in[size_t(y) * width + x] != 1) ++s.missed;
    }
  }
  // Inside pixels farther than 3 pixels from any pixel with a hit: the margins are ~1-2 pixels.
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      if (in[size_t(y) * width + x] != 1) continue;
      bool near = false;
      for (int dy = -3; dy <= 3 && !near; ++dy)
        for (int dx = -3; dx <= 3 && !near; ++dx) {
          const int qx = x + dx, qy = y + dy;
          near = qx >= 0 && qy >= 0 && qx < width && qy < height && hit[size_t(qy) * width + qx];
        }
      s.far += near ? 0 : 1;
    }
  }
  return s;
}

TEST(PixelOrder, EveryPixelThatSeesTheBoxIsInsideAndFewOthersAre) {
  std::mt19937 rng(12345);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  size_t missed = 0, far = 0, inside = 0, hits = 0, cases = 0, partial = 0, whole = 0, widened = 0, fewer = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const int width = 24 + int(rng() % 40), height = 16 + int(rng() % 40);
    // A box of 20-60 voxels per axis, rotated, scaled to 1/20-1/10 world units per voxel, moved.
    const glm::vec3 lo(float(rng() % 10), float(rng() % 10), float(rng() % 10));
    const glm::vec3 hi = lo + glm::vec3(20 + rng() % 40, 20 + rng() % 40, 20 + rng() % 40);
    glm::mat4 m = glm::translate(glm::mat4(1.0f), glm::vec3(u(rng), u(rng), u(rng)));
    m = glm::rotate(m, 3.0f * u(rng), glm::normalize(glm::vec3(u(rng), u(rng), u(rng)) + glm::vec3(0.0f, 0.0f, 1e-3f)));
    m = glm::scale(m, glm::vec3(0.05f + 0.05f * std::abs(u(rng))));
    const glm::vec3 centre = glm::vec3(m * glm::vec4(0.5f * (lo + hi), 1.0f));
    // Cameras from 3 to 12 units away, looking near the box (sometimes past it).
    const glm::vec3 dir = glm::normalize(glm::vec3(u(rng), u(rng), u(rng)) + glm::vec3(0.0f, 0.0f, 1e-3f));
    const glm::vec3 position = centre + (3.0f + 4.5f * (u(rng) + 1.0f)) * dir;
    const glm::vec3 lookAt = centre + 1.5f * glm::vec3(u(rng), u(rng), u(rng));
    const shared::GpuCamera cam = cameraAt(position, lookAt, 25.0f + 20.0f * (u(rng) + 1.0f), width, height);
    // Every other trial with occupied cells: a 4 x 4 x 4 grid over the box, each cell kept with
    // probability 0.3 (at least one).
    std::vector<IndexBox> cells;
    if (trial % 2 == 1) {
      const glm::vec3 side = (hi - lo) / 4.0f;
      for (int c = 0; c < 64; ++c) {
        if (rng() % 10 >= 3 && !(c == 63 && cells.empty())) continue;
        const glm::vec3 at = lo + side * glm::vec3(c % 4, (c / 4) % 4, c / 16);
        cells.push_back({at, at + side});
      }
    }
    const Split s = check(cam, width, height, footprintOf(lo, hi, m, false, cells), rng);
    missed += s.missed;
    // (Where the box reaches the camera's plane every pixel is inside, by design: not counted; a
    // cell's projection is its bounding rectangle, looser than a hull: the cells may only take
    // pixels away from the box's.)
    const bool everything = s.inside == size_t(width) * height;
    if (cells.empty()) {
      far += everything ? 0 : s.far;
    } else {
      const size_t box = volumePixelOrder(cam, width, height, footprintOf(lo, hi, m)).inside;
      widened += s.inside > box ? 1 : 0;
      fewer += s.inside < box ? 1 : 0;
    }
    whole += everything ? 1 : 0;
    inside += s.inside;
    hits += s.hits;
    partial += s.inside > 0 && s.inside < size_t(width) * height ? 1 : 0;
    ++cases;
  }
  std::printf("[pixel order] %zu cameras (%zu see part of the box, %zu have every pixel inside): %zu pixels with a "
              "hit, %zu inside, %zu hit pixels left out, %zu inside pixels farther than 3 px from a hit (box only); "
              "cells took pixels away in %zu cases\n",
              cases, partial, whole, hits, inside, missed, far, fewer);
  EXPECT_EQ(missed, 0u) << "a pixel that sees the box must be inside";
  EXPECT_EQ(far, 0u) << "inside pixels must be near the box's projection";
  EXPECT_GT(partial, cases / 2) << "the cameras must mostly see part of the box";
  EXPECT_LT(whole, cases / 10) << "few boxes may reach the camera's plane";
  EXPECT_EQ(widened, 0u) << "occupied cells must never add pixels to the box's";
  EXPECT_GT(fewer, cases / 4) << "occupied cells must usually take pixels away";
}

TEST(PixelOrder, BoxesBehindAroundOrEmpty) {
  const glm::vec3 lo(0.0f), hi(40.0f);
  const glm::mat4 m = glm::scale(glm::mat4(1.0f), glm::vec3(0.05f));  // the box [0, 2]^3 in world units
  // Behind the camera: no pixel. Around it: every pixel. Empty volume: none.
  const shared::GpuCamera away = cameraAt({1.0f, 1.0f, 5.0f}, {1.0f, 1.0f, 9.0f}, 40.0f, 32, 24);
  EXPECT_EQ(volumePixelOrder(away, 32, 24, footprintOf(lo, hi, m)).inside, 0u);
  const shared::GpuCamera in = cameraAt({1.0f, 1.0f, 1.0f}, {1.0f, 1.0f, 9.0f}, 40.0f, 32, 24);
  EXPECT_EQ(volumePixelOrder(in, 32, 24, footprintOf(lo, hi, m)).inside, 32u * 24u);
  const shared::GpuCamera front = cameraAt({1.0f, 1.0f, 8.0f}, {1.0f, 1.0f, 1.0f}, 40.0f, 32, 24);
  const PixelOrder seen = volumePixelOrder(front, 32, 24, footprintOf(lo, hi, m));
  EXPECT_GT(seen.inside, 0u);
  EXPECT_LT(seen.inside, 32u * 24u);
  EXPECT_EQ(volumePixelOrder(front, 32, 24, footprintOf(lo, hi, m, true)).inside, 0u);
  // One occupied cell, the box's far corner: fewer pixels than the whole box.
  const PixelOrder cell = volumePixelOrder(front, 32, 24, footprintOf(lo, hi, m, false, {{glm::vec3(30.0f), hi}}));
  EXPECT_GT(cell.inside, 0u);
  EXPECT_LT(cell.inside, seen.inside / 4);
  // The list holds every pixel once, inside ones first, each part in tile order (8 x 8 tiles
  // row-major, each tile row-major).
  std::set<uint32_t> all(seen.pixels.begin(), seen.pixels.end());
  EXPECT_EQ(all.size(), 32u * 24u);
  auto key = [](uint32_t p) {
    const uint32_t x = p & 0xffffu, y = p >> 16;
    return std::make_tuple(y / 8, x / 8, y, x);
  };
  auto tileOrder = [&](uint32_t a, uint32_t b) { return key(a) < key(b); };
  EXPECT_TRUE(std::is_sorted(seen.pixels.begin(), seen.pixels.begin() + seen.inside, tileOrder));
  EXPECT_TRUE(std::is_sorted(seen.pixels.begin() + seen.inside, seen.pixels.end(), tileOrder));
  const PixelOrder every = allPixels(20, 12);  // partial tiles at the right and bottom edges
  EXPECT_EQ(every.inside, 240u);
  EXPECT_TRUE(std::is_sorted(every.pixels.begin(), every.pixels.end(), tileOrder));
  EXPECT_EQ(std::set<uint32_t>(every.pixels.begin(), every.pixels.end()).size(), 240u);
}

// The ray through image point (px, py) meets the front of triangle (a, b, c) (the side its
// counter-clockwise normal points to: surf_emitted), at t > 0 (Möller-Trumbore, double).
bool rayMeetsFront(const shared::GpuCamera& cam, int width, int height, double px, double py, glm::dvec3 a,
                   glm::dvec3 b, glm::dvec3 c) {
  const double sx = (2.0 * px / width - 1.0) * cam.tanHalfFovY * cam.aspect;
  const double sy = (1.0 - 2.0 * py / height) * cam.tanHalfFovY;
  const glm::dvec3 d = glm::dvec3(cam.forward) + sx * glm::dvec3(cam.right) + sy * glm::dvec3(cam.up);
  const glm::dvec3 o(cam.position), e1 = b - a, e2 = c - a;
  if (!(glm::dot(glm::cross(e1, e2), d) < 0.0)) return false;  // the back, or edge-on
  const glm::dvec3 p = glm::cross(d, e2);
  const double det = glm::dot(e1, p);
  if (det == 0.0) return false;
  const glm::dvec3 s = o - a;
  const double u = glm::dot(s, p) / det;
  const glm::dvec3 q = glm::cross(s, e1);
  const double v = glm::dot(d, q) / det, t = glm::dot(e2, q) / det;
  return u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0;
}

bool marked(const std::vector<uint32_t>& mask, int width, int x, int y) {
  const size_t i = size_t(y) * size_t(width) + size_t(x);
  return ((mask[i / 32] >> (i % 32)) & 1u) != 0u;
}

size_t markedCount(const std::vector<uint32_t>& mask, int width, int height) {
  size_t n = 0;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) n += marked(mask, width, x, y) ? 1 : 0;
  return n;
}

// A packed rectangle of emitterPixelRects: (u0, v0) and (u1, v1).
struct UnpackedRect {
  double u0, v0, u1, v1;
  explicit UnpackedRect(uint64_t r)
      : u0(double(r & 0xffffu) / 65535.0), v0(double(r >> 16 & 0xffffu) / 65535.0),
        u1(double(r >> 32 & 0xffffu) / 65535.0), v1(double(r >> 48) / 65535.0) {}
};

// A random camera (16-55 x 12-51 pixels, 25-65 degrees) and 12 triangles of every size (from a
// few hundredths of a pixel to larger than the image), facing any way: 9 centred in front of the
// camera, 3 around or behind it (some across its plane).
struct EmitterTrial {
  int width = 0, height = 0;
  shared::GpuCamera cam{};
  std::vector<glm::vec3> vertices;
};
EmitterTrial randomEmitterTrial(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  EmitterTrial t;
  t.width = 16 + int(rng() % 40), t.height = 12 + int(rng() % 40);
  const glm::vec3 position(4.0f * u(rng), 4.0f * u(rng), 4.0f * u(rng));
  const glm::vec3 lookAt = position + glm::normalize(glm::vec3(u(rng), u(rng), u(rng)) + glm::vec3(0.0f, 0.0f, 1e-3f));
  t.cam = cameraAt(position, lookAt, 25.0f + 20.0f * (u(rng) + 1.0f), t.width, t.height);
  for (int k = 0; k < 12; ++k) {
    // Centres in front (most), around or behind the camera; sizes from 1e-3 to 3 units.
    const float ahead = k < 9 ? 1.0f + 5.0f * (u(rng) + 1.0f) : 2.0f * u(rng);
    const glm::vec3 centre = position + ahead * t.cam.forward + 2.0f * glm::vec3(u(rng), u(rng), u(rng));
    const float size = std::pow(10.0f, -3.0f + 1.75f * (u(rng) + 1.0f));
    for (int c = 0; c < 3; ++c) t.vertices.push_back(centre + size * glm::vec3(u(rng), u(rng), u(rng)));
  }
  return t;
}

// render/pixel_order.h emitterPixelRects and its mask: every pixel one of whose camera rays meets
// an emitter's front is marked (ReSTIR traces the lamps seen directly in those pixels only, so a
// pixel left out wrongly would lose its lamp), and every such ray's (u, v) lies in its pixel's
// rectangle (the lamp reservoir draws its rays there only, so a point left out would lose its part
// of the lamp). Random cameras and triangles of every size (from a few hundredths of a pixel to
// larger than the image), facing any way, some across or behind the camera's plane; 24 rays per
// pixel (its corners, centre and random points) in double precision.
TEST(PixelOrder, EveryPixelThatSeesAnEmittersFrontIsMarked) {
  std::mt19937 rng(777);
  size_t missed = 0, hits = 0, marks = 0, pixels = 0, rays = 0, outsideRect = 0;
  double rectArea = 0.0;
  for (int trial = 0; trial < 40; ++trial) {
    const EmitterTrial t = randomEmitterTrial(rng);
    const int width = t.width, height = t.height;
    const shared::GpuCamera& cam = t.cam;
    const std::vector<glm::vec3>& vertices = t.vertices;
    const std::vector<uint64_t> rects = emitterPixelRects(cam, width, height, vertices);
    ASSERT_EQ(rects.size(), size_t(width) * height);
    const std::vector<uint32_t> mask = emitterPixelMask(rects);
    ASSERT_EQ(mask.size(), (size_t(width) * height + 31) / 32);
    std::uniform_real_distribution<double> w(0.0, 1.0);
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        const uint64_t rect = rects[size_t(y) * width + x];
        const UnpackedRect q(rect);
        if (rect != kNoEmitterRect) rectArea += (q.u1 - q.u0) * (q.v1 - q.v0);
        bool any = false;
        for (int r = 0; r < 24; ++r) {
          const double fx = r < 4 ? (r & 1) : r == 4 ? 0.5 : w(rng), fy = r < 4 ? (r >> 1) : r == 4 ? 0.5 : w(rng);
          bool hit = false;
          for (size_t k = 0; k < vertices.size() && !hit; k += 3) {
            hit = rayMeetsFront(cam, width, height, x + fx, y + fy, glm::dvec3(vertices[k]), glm::dvec3(vertices[k + 1]),
                                glm::dvec3(vertices[k + 2]));
          }
          any = any || hit;
          rays += hit ? 1 : 0;
          outsideRect += hit && !(fx >= q.u0 && fx <= q.u1 && fy >= q.v0 && fy <= q.v1) ? 1 : 0;
        }
        hits += any ? 1 : 0;
        missed += any && !marked(mask, width, x, y) ? 1 : 0;
      }
    }
    marks += markedCount(mask, width, height);
    pixels += size_t(width) * height;
  }
  std::printf("[pixel order] emitters: %zu of %zu pixels see a front, %zu marked, %zu missed; %zu rays meet a front, "
              "%zu outside their pixel's rectangle; the rectangles cover %.3f of a marked pixel on average\n",
              hits, pixels, marks, missed, rays, outsideRect, rectArea / double(marks));
  EXPECT_EQ(missed, 0u) << "a pixel that sees an emitter's front must be marked";
  EXPECT_EQ(outsideRect, 0u) << "a ray that meets an emitter's front must lie in its pixel's rectangle";
  // (Most of these triangles are larger than a pixel: the rectangles leave out about a tenth.)
  EXPECT_LT(rectArea, 0.95 * double(marks)) << "the rectangles must leave parts of the pixels out";
  EXPECT_GT(hits, pixels / 20) << "too few pixels see an emitter for the test to mean much";
  EXPECT_LT(marks, pixels * 3 / 4) << "the mask must leave pixels out";
}

// render/pixel_order.h emitterPixelTriangles: the pieces the lamp reservoir draws its rays on.
// Every ray of a pixel that meets an emitter's front lies on a piece of that emitter in that pixel
// (a point left out would lose its part of the lamp: the estimator's unbiasedness rests on it),
// the pieces lie in the pixel's square and an emitter's pieces in one pixel cover at most the
// square; and they are tight: the exact projection's area in the pixel plus the growth's margin.
// Random cameras and triangles as above (sizes from a thousandth of a unit), 24 rays a pixel.
TEST(PixelOrder, EveryRayThatMeetsAnEmittersFrontLiesOnOneOfItsPieces) {
  std::mt19937 rng(778);
  size_t rays = 0, outside = 0, badCorners = 0, tooLarge = 0, pieces = 0;
  double pieceArea = 0.0, exactArea = 0.0;
  auto inTriangle = [](glm::dvec2 p, glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) {
    auto side = [](glm::dvec2 o, glm::dvec2 d, glm::dvec2 q) { return (d.x - o.x) * (q.y - o.y) - (d.y - o.y) * (q.x - o.x); };
    // (up to 1e-9 of a pixel: a pixel's corner may round to a hair outside its pieces, a set of
    // measure 0 that no drawn (u, v) meets)
    const double s0 = side(a, b, p), s1 = side(b, c, p), s2 = side(c, a, p), e = 1e-9;
    return (s0 >= -e && s1 >= -e && s2 >= -e) || (s0 <= e && s1 <= e && s2 <= e);
  };
  for (int trial = 0; trial < 40; ++trial) {
    const EmitterTrial t = randomEmitterTrial(rng);
    const int width = t.width, height = t.height;
    const shared::GpuCamera& cam = t.cam;
    const std::vector<glm::vec3>& vertices = t.vertices;
    const EmitterPixelLists lists = emitterPixelTriangles(cam, width, height, vertices);
    ASSERT_EQ(lists.begin.size(), size_t(width) * height + 1);
    std::vector<double> trianglePieces(vertices.size() / 3, 0.0);  // each triangle's pieces' area
    ASSERT_EQ(lists.begin.back(), lists.pieces.size());
    std::uniform_real_distribution<double> w(0.0, 1.0);
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        const size_t i = size_t(y) * width + x;
        std::vector<double> area(vertices.size() / 3, 0.0);
        for (uint32_t j = lists.begin[i]; j < lists.begin[i + 1]; ++j) {
          const EmitterPiece& e = lists.pieces[j];
          for (glm::vec2 c : {e.a, e.b, e.c}) badCorners += c.x >= 0.0f && c.x <= 1.0f && c.y >= 0.0f && c.y <= 1.0f ? 0 : 1;
          area[e.triangle] += e.area;
          trianglePieces[e.triangle] += e.area;
          ++pieces;
        }
        for (double a : area) tooLarge += a <= 1.0 + 1e-5 ? 0 : 1;
        for (int r = 0; r < 24; ++r) {
          const double fx = r < 4 ? (r & 1) : r == 4 ? 0.5 : w(rng), fy = r < 4 ? (r >> 1) : r == 4 ? 0.5 : w(rng);
          for (size_t k = 0; k < vertices.size(); k += 3) {
            if (!rayMeetsFront(cam, width, height, x + fx, y + fy, glm::dvec3(vertices[k]), glm::dvec3(vertices[k + 1]),
                               glm::dvec3(vertices[k + 2]))) {
              continue;
            }
            ++rays;
            bool on = false;
            for (uint32_t j = lists.begin[i]; j < lists.begin[i + 1] && !on; ++j) {
              const EmitterPiece& e = lists.pieces[j];
              on = e.triangle == k / 3 && inTriangle({fx, fy}, glm::dvec2(e.a), glm::dvec2(e.b), glm::dvec2(e.c));
            }
            outside += on ? 0 : 1;
            if (!on && outside < 6) {
              std::printf("off: trial %d pixel (%d, %d) ray (%.6f, %.6f) triangle %zu:", trial, x, y, fx, fy, k / 3);
              for (uint32_t j = lists.begin[i]; j < lists.begin[i + 1]; ++j) {
                const EmitterPiece& e = lists.pieces[j];
                if (e.triangle == k / 3) std::printf(" [(%.4f %.4f) (%.4f %.4f) (%.4f %.4f)]", e.a.x, e.a.y, e.b.x, e.b.y, e.c.x, e.c.y);
              }
              std::printf("\n");
            }
          }
        }
      }
    }
    // The exact projections' areas of the triangles wholly in front of the camera's plane (the
    // others' pieces are whole pixels), against their pieces'.
    const glm::dvec3 pos(cam.position);
    for (size_t k = 0; k < vertices.size(); k += 3) {
      std::vector<glm::dvec2> corners;
      bool front = true;
      for (size_t c = 0; c < 3; ++c) {
        const glm::dvec3 d = glm::dvec3(vertices[k + c]) - pos;
        const double z = glm::dot(d, glm::dvec3(cam.forward));
        front = front && z > 1e-3;
        corners.push_back({(glm::dot(d, glm::dvec3(cam.right)) / z / (cam.tanHalfFovY * cam.aspect) + 1.0) * 0.5 * width,
                           (1.0 - glm::dot(d, glm::dvec3(cam.up)) / z / cam.tanHalfFovY) * 0.5 * height});
      }
      const glm::dvec3 n = glm::cross(glm::dvec3(vertices[k + 1] - vertices[k]), glm::dvec3(vertices[k + 2] - vertices[k]));
      if (!front || glm::dot(n, pos - glm::dvec3(vertices[k])) <= 0.0) continue;
      for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) exactArea += polygonAreaInPixel(corners, x, y);
      pieceArea += trianglePieces[k / 3];
    }
  }
  std::printf("[pixel order] emitter pieces: %zu pieces, %zu rays meet a front, %zu of them off their emitter's "
              "pieces; the pieces of the triangles in front of the camera's plane cover %.4f square pixels, their exact projections %.4f\n",
              pieces, rays, outside, pieceArea, exactArea);
  EXPECT_EQ(outside, 0u) << "a ray that meets an emitter's front must lie on one of that emitter's pieces";
  EXPECT_EQ(badCorners, 0u) << "the pieces must lie in the pixel's square";
  EXPECT_EQ(tooLarge, 0u) << "an emitter's pieces in a pixel must cover at most the pixel";
  EXPECT_GT(rays, 1000u) << "too few rays meet an emitter for the test to mean much";
  // Tight: the pieces cover the projections and little more.
  EXPECT_GE(pieceArea, exactArea);
  EXPECT_LT(pieceArea, 1.1 * exactArea) << "the pieces must follow the projections, not their rectangles";
}

// What the mask leaves out: a triangle whose back faces the camera, one behind the camera's plane;
// and a small one in the image marks the pixel it covers and at most its neighbours within the
// margin (a sixteenth of a pixel).
TEST(PixelOrder, EmitterMaskLeavesOutBacksAndTheUnseen) {
  const int width = 32, height = 24;
  const shared::GpuCamera cam = cameraAt({0.0f, 0.0f, 5.0f}, {0.0f, 0.0f, 0.0f}, 40.0f, width, height);
  auto count = [&](std::vector<glm::vec3> v) { return markedCount(emitterPixelMask(emitterPixelRects(cam, width, height, v)), width, height); };
  // Facing the camera (counter-clockwise seen from +z: its normal points at the camera) and its back.
  const std::vector<glm::vec3> front = {{-1.0f, -1.0f, 0.0f}, {1.0f, -1.0f, 0.0f}, {0.0f, 1.0f, 0.0f}};
  const std::vector<glm::vec3> back = {front[0], front[2], front[1]};
  EXPECT_GT(count(front), 20u);
  EXPECT_EQ(count(back), 0u);
  // Behind the camera (which looks towards -z), facing it.
  EXPECT_EQ(count({{-1.0f, -1.0f, 8.0f}, {0.0f, 1.0f, 8.0f}, {1.0f, -1.0f, 8.0f}}), 0u);
  // Across the camera's plane: marks the pixels towards its front part (not none, not all).
  const size_t across = count({{-3.0f, 0.5f, 7.0f}, {-3.0f, -0.5f, 7.0f}, {-0.5f, 0.0f, 3.0f}});
  EXPECT_GT(across, 0u);
  EXPECT_LT(across, size_t(width * height));
  // A hundredth of a pixel wide, at a pixel's centre: that pixel alone.
  const double pixel = 2.0 * 5.0 * std::tan(glm::radians(20.0)) / height;  // world units per pixel at z = 0
  const glm::vec3 c(float((0.5 - 0.5 * width + 10.0) * pixel), float((0.5 * height - 0.5 - 7.0) * pixel), 0.0f);
  const float h = float(0.005 * pixel);
  const std::vector<uint64_t> rects = emitterPixelRects(cam, width, height, {c + glm::vec3(-h, -h, 0.0f), c + glm::vec3(h, -h, 0.0f), c + glm::vec3(0.0f, h, 0.0f)});
  const std::vector<uint32_t> one = emitterPixelMask(rects);
  EXPECT_EQ(markedCount(one, width, height), 1u);
  EXPECT_TRUE(marked(one, width, 10, 7));
  // Its rectangle: the hundredth of a pixel around the centre grown by the margin on each side.
  const UnpackedRect q(rects[7 * width + 10]);
  const double m = kEmitterPixelMargin + 0.006;
  EXPECT_NEAR(q.u0, 0.5 - m, 0.002);
  EXPECT_NEAR(q.u1, 0.5 + m, 0.002);
  EXPECT_NEAR(q.v0, 0.5 - m, 0.002);
  EXPECT_NEAR(q.v1, 0.5 + m, 0.002);
  EXPECT_EQ(std::count(rects.begin(), rects.end(), kNoEmitterRect), std::ptrdiff_t(width * height - 1));
}

}  // namespace
