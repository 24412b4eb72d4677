#include "render/pixel_order.h"

#include "core/error.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace plume {

namespace {

// Calls f(x, y) for every pixel in tile order (kPixelOrderTile² tiles row-major, each tile's
// pixels row-major).
template <typename F>
void forEachInTileOrder(int width, int height, F&& f) {
  const int t = kPixelOrderTile;
  for (int ty = 0; ty < height; ty += t)
    for (int tx = 0; tx < width; tx += t)
      for (int y = ty; y < std::min(ty + t, height); ++y)
        for (int x = tx; x < std::min(tx + t, width); ++x) f(x, y);
}

}  // namespace

PixelOrder allPixels(int width, int height) {
  PLUME_CHECK(width > 0 && height > 0 && width <= 65536 && height <= 65536);
  PixelOrder order;
  order.pixels.reserve(size_t(width) * size_t(height));
  forEachInTileOrder(width, height, [&](int x, int y) { order.pixels.push_back(packPixel(uint32_t(x), uint32_t(y))); });
  order.inside = uint32_t(order.pixels.size());
  return order;
}

namespace {

// A projected box: its corners on the image, in pixels (x right, y down: cam_direction's
// inverse), and where it lies: 0 in front of the camera's plane, 1 wholly behind it, 2 across it.
struct Projected {
  std::array<glm::dvec2, 8> p;
  int side = 0;
};

Projected project(const shared::GpuCamera& cam, int width, int height, const IndexBox& box, const glm::mat4& indexToWorld) {
  const glm::dvec3 pos(cam.position), fwd(cam.forward), right(cam.right), up(cam.up);
  const double tanY = double(cam.tanHalfFovY), tanX = tanY * double(cam.aspect);
  Projected out;
  int behind = 0;
  bool finite = true;
  for (int c = 0; c < 8; ++c) {
    const glm::vec3 corner((c & 1) ? box.hi.x + kPixelOrderBoxMargin : box.lo.x - kPixelOrderBoxMargin,
                           (c & 2) ? box.hi.y + kPixelOrderBoxMargin : box.lo.y - kPixelOrderBoxMargin,
                           (c & 4) ? box.hi.z + kPixelOrderBoxMargin : box.lo.z - kPixelOrderBoxMargin);
    const glm::dvec3 d = glm::dvec3(glm::vec3(indexToWorld * glm::vec4(corner, 1.0f))) - pos;
    const double z = glm::dot(d, fwd);
    if (!(z > 1e-9 * std::max(1.0, glm::length(d)))) {
      ++behind;
      continue;
    }
    const double sx = glm::dot(d, right) / z / tanX, sy = glm::dot(d, up) / z / tanY;
    out.p[size_t(c)] = glm::dvec2((sx + 1.0) * 0.5 * width, (1.0 - sy) * 0.5 * height);
    finite = finite && std::isfinite(out.p[size_t(c)].x) && std::isfinite(out.p[size_t(c)].y);
  }
  // Every ray leaves the camera forwards (cam_direction: forward plus a sideways part), so a box
  // wholly behind its plane is seen by no pixel; one that reaches the plane from in front (or
  // holds the camera) projects without bound.
  out.side = behind == 8 ? 1 : behind != 0 || !finite ? 2 : 0;
  return out;
}

// The pixel columns [x0, x1) of a row whose squares may meet [xmin, xmax] grown by the margin.
void columns(double xmin, double xmax, int width, int& x0, int& x1) {
  const double m = kPixelOrderPixelMargin;
  x0 = int(std::clamp(std::floor(xmin - m), 0.0, double(width)));
  x1 = int(std::clamp(std::ceil(xmax + m) + 1.0, 0.0, double(width)));
}

}  // namespace

PixelOrder volumePixelOrder(const shared::GpuCamera& cam, int width, int height, const VolumeFootprint& volume) {
  PLUME_CHECK(width > 0 && height > 0 && width <= 65536 && height <= 65536);
  const size_t n = size_t(width) * size_t(height);
  auto all = [&](bool inside) {
    PixelOrder order = allPixels(width, height);
    if (!inside) order.inside = 0;
    return order;
  };
  if (volume.empty) return all(false);
  const Projected bounds = project(cam, width, height, volume.bounds, volume.indexToWorld);
  if (bounds.side == 1) return all(false);
  if (bounds.side == 2) return all(true);
  const std::array<glm::dvec2, 8>& p = bounds.p;
  // Per row of pixels: the x-extent of the bounds' hull within the row's slab (grown by the
  // margin) is the extent of the corners inside the slab and of every segment between two corners
  // where it crosses the slab's edges (points of the hull, and they include the hull's own
  // vertices there).
  std::vector<char> in(n, 0);
  const double m = kPixelOrderPixelMargin;
  for (int y = 0; y < height; ++y) {
    const double y0 = y - m, y1 = y + 1 + m;
    double xmin = std::numeric_limits<double>::infinity(), xmax = -xmin;
    auto add = [&](double x) {
      xmin = std::min(xmin, x);
      xmax = std::max(xmax, x);
    };
    for (int a = 0; a < 8; ++a) {
      if (p[a].y >= y0 && p[a].y <= y1) add(p[a].x);
      for (int b = a + 1; b < 8; ++b) {
        const double ya = p[a].y, yb = p[b].y;
        for (double e : {y0, y1}) {
          if ((ya - e) * (yb - e) < 0.0) add(p[a].x + (p[b].x - p[a].x) * (e - ya) / (yb - ya));
        }
      }
    }
    if (!(xmin <= xmax)) continue;
    int x0, x1;
    columns(xmin, xmax, width, x0, x1);
    for (int x = x0; x < x1; ++x) in[size_t(y) * width + x] = 1;
  }
  // Within the bounds' pixels, those of the occupied cells' bounding rectangles only.
  if (!volume.cells.empty()) {
    std::vector<char> cell(n, 0);
    for (const IndexBox& box : volume.cells) {
      const Projected c = project(cam, width, height, box, volume.indexToWorld);
      if (c.side == 1) continue;
      if (c.side == 2) {
        std::fill(cell.begin(), cell.end(), char(1));
        break;
      }
      double xmin = c.p[0].x, xmax = xmin, ymin = c.p[0].y, ymax = ymin;
      for (const glm::dvec2& q : c.p) {
        xmin = std::min(xmin, q.x);
        xmax = std::max(xmax, q.x);
        ymin = std::min(ymin, q.y);
        ymax = std::max(ymax, q.y);
      }
      int x0, x1, yb0, yb1;
      columns(xmin, xmax, width, x0, x1);
      columns(ymin, ymax, height, yb0, yb1);
      for (int y = yb0; y < yb1; ++y)
        for (int x = x0; x < x1; ++x) cell[size_t(y) * width + x] = 1;
    }
    for (size_t i = 0; i < n; ++i) in[i] = char(in[i] && cell[i]);
  }
  PixelOrder order;
  order.pixels.reserve(n);
  for (int pass = 1; pass >= 0; --pass) {
    forEachInTileOrder(width, height, [&](int x, int y) {
      if (in[size_t(y) * width + x] == pass) order.pixels.push_back(packPixel(uint32_t(x), uint32_t(y)));
    });
  }
  order.inside = uint32_t(std::count(in.begin(), in.end(), char(1)));
  return order;
}

namespace {
// An emitter triangle's projection in pixel units (x right, y down): the corners of its part in
// front of the camera's plane, and their bounding rectangle grown by kEmitterPixelMargin.
struct EmitterProjection {
  std::array<glm::dvec2, 4> corners;
  int count = 0;
  bool clipped = false;  // the camera's plane cut the triangle
  double xmin = 0, ymin = 0, xmax = 0, ymax = 0;
};

// Every pixel the emitter triangle k may be seen in (render/pixel_order.h emitterPixelRects: the
// camera in front of its plane, its projection's bounding rectangle clipped to the front of the
// camera's plane and grown by kEmitterPixelMargin): visit(k, x, y, projection). False when a
// projection is not a number (the caller then takes every pixel, whole).
template <typename Visit>
bool forEachEmitterPixel(const shared::GpuCamera& cam, int width, int height, const std::vector<glm::vec3>& vertices,
                         Visit visit) {
  PLUME_CHECK(width > 0 && height > 0 && width <= 65536 && height <= 65536 && vertices.size() % 3 == 0);
  const glm::dvec3 pos(cam.position), fwd(cam.forward), right(cam.right), up(cam.up);
  const double tanY = double(cam.tanHalfFovY), tanX = tanY * double(cam.aspect);
  for (size_t k = 0; k < vertices.size(); k += 3) {
    const glm::dvec3 v[3] = {glm::dvec3(vertices[k]), glm::dvec3(vertices[k + 1]), glm::dvec3(vertices[k + 2])};
    // The camera behind the triangle's plane sees its back only (up to a tolerance far above the
    // device's rounding of the normal's cross product, even for a sliver; a degenerate triangle is kept).
    const glm::dvec3 e1 = v[1] - v[0], e2 = v[2] - v[0];
    const double tolerance = 1e-5 * glm::length(e1) * glm::length(e2) * (glm::length(e1) + glm::length(e2) + glm::length(pos - v[0]));
    if (glm::dot(glm::cross(e1, e2), pos - v[0]) < -tolerance) continue;
    // Clipped to z >= eps in front of the camera (every ray leaves it forwards: cam_direction).
    double z[3];
    double eps = 0.0;
    for (int i = 0; i < 3; ++i) {
      z[i] = glm::dot(v[i] - pos, fwd);
      eps = std::max(eps, 1e-9 * std::max(1.0, glm::length(v[i] - pos)));
    }
    std::array<glm::dvec3, 4> poly;
    int count = 0;
    for (int i = 0; i < 3; ++i) {
      const int j = (i + 1) % 3;
      if (z[i] >= eps) poly[size_t(count++)] = v[i];
      if ((z[i] - eps) * (z[j] - eps) < 0.0) poly[size_t(count++)] = v[i] + (v[j] - v[i]) * ((eps - z[i]) / (z[j] - z[i]));
    }
    if (count == 0) continue;
    EmitterProjection pr;
    pr.count = count;
    pr.clipped = !(z[0] >= eps && z[1] >= eps && z[2] >= eps);
    double xmin = std::numeric_limits<double>::infinity(), xmax = -xmin, ymin = xmin, ymax = -xmin;
    for (int i = 0; i < count; ++i) {
      const glm::dvec3 d = poly[size_t(i)] - pos;
      const double zc = std::max(glm::dot(d, fwd), eps);
      const double px = (glm::dot(d, right) / zc / tanX + 1.0) * 0.5 * width;
      const double py = (1.0 - glm::dot(d, up) / zc / tanY) * 0.5 * height;
      pr.corners[size_t(i)] = {px, py};
      xmin = std::min(xmin, px);
      xmax = std::max(xmax, px);
      ymin = std::min(ymin, py);
      ymax = std::max(ymax, py);
    }
    if (!(std::isfinite(xmin) && std::isfinite(xmax) && std::isfinite(ymin) && std::isfinite(ymax))) return false;
    // The pixels [x0, x1) x [y0, y1) whose squares meet the rectangle grown by the margin.
    const double m = kEmitterPixelMargin;
    xmin -= m, xmax += m, ymin -= m, ymax += m;
    const int x0 = int(std::clamp(std::floor(xmin), 0.0, double(width)));
    const int x1 = int(std::clamp(std::floor(xmax) + 1.0, 0.0, double(width)));
    const int y0 = int(std::clamp(std::floor(ymin), 0.0, double(height)));
    const int y1 = int(std::clamp(std::floor(ymax) + 1.0, 0.0, double(height)));
    pr.xmin = xmin, pr.ymin = ymin, pr.xmax = xmax, pr.ymax = ymax;
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) visit(uint32_t(k / 3), x, y, pr);
  }
  return true;
}
}  // namespace

std::vector<uint64_t> emitterPixelRects(const shared::GpuCamera& cam, int width, int height,
                                        const std::vector<glm::vec3>& vertices) {
  std::vector<uint64_t> rects(size_t(width) * size_t(height), kNoEmitterRect);
  auto fixed = [](double t, bool up) { return uint64_t(up ? std::ceil(t * 65535.0) : std::floor(t * 65535.0)); };
  // Each pixel's rectangle: the union of the triangles' parts inside it.
  const bool finite = forEachEmitterPixel(cam, width, height, vertices, [&](uint32_t, int x, int y, const EmitterProjection& p) {
    uint64_t& r = rects[size_t(y) * size_t(width) + size_t(x)];
    const uint64_t a = std::min(r & 0xffffu, fixed(std::clamp(p.xmin - x, 0.0, 1.0), false));
    const uint64_t b = std::min(r >> 16 & 0xffffu, fixed(std::clamp(p.ymin - y, 0.0, 1.0), false));
    const uint64_t c = std::max(r >> 32 & 0xffffu, fixed(std::clamp(p.xmax - x, 0.0, 1.0), true));
    const uint64_t d = std::max(r >> 48, fixed(std::clamp(p.ymax - y, 0.0, 1.0), true));
    r = a | b << 16 | c << 32 | d << 48;
  });
  if (!finite) std::fill(rects.begin(), rects.end(), kWholePixelRect);  // (not a number: every pixel, whole)
  return rects;
}

namespace {
// The convex polygon p (pixel units) cut to pixel (x, y)'s square (Sutherland-Hodgman), in that
// pixel's own (u, v).
std::vector<glm::dvec2> clipToPixel(std::vector<glm::dvec2> p, int x, int y) {
  for (glm::dvec2& c : p) c -= glm::dvec2(x, y);
  std::vector<glm::dvec2> q;
  for (int side = 0; side < 4; ++side) {
    const int axis = side / 2;
    const double bound = double(side % 2), sign = side % 2 ? -1.0 : 1.0;
    q.clear();
    for (size_t i = 0; i < p.size(); ++i) {
      const glm::dvec2 a = p[i], b = p[(i + 1) % p.size()];
      const double da = sign * (a[axis] - bound), db = sign * (b[axis] - bound);
      if (da >= 0.0) q.push_back(a);
      if ((da >= 0.0) != (db >= 0.0)) q.push_back(a + (b - a) * (da / (da - db)));
    }
    std::swap(p, q);
  }
  for (glm::dvec2& c : p) c = glm::clamp(c, 0.0, 1.0);  // (rounding's overshoot)
  return p;
}

double twiceArea(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) { return std::abs((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x)); }

// The region of pixel (x, y) that the lamp reservoir draws emitter triangle p's rays on: its
// projection with every edge moved out by kEmitterRegionGrowth (the triangle scaled about its
// incentre), cut to the square; the whole square where the camera's plane cuts the triangle;
// nothing where the projection is a segment (seen edge on).
std::vector<glm::dvec2> emitterRegion(const EmitterProjection& p, int x, int y) {
  if (p.clipped) return {{0.0, 0.0}, {1.0, 0.0}, {1.0, 1.0}, {0.0, 1.0}};
  const glm::dvec2 a = p.corners[0], b = p.corners[1], c = p.corners[2];
  const double la = glm::length(b - c), lb = glm::length(c - a), lc = glm::length(a - b);
  const double perimeter = la + lb + lc, inradius = twiceArea(a, b, c) / perimeter;
  if (!(inradius > 1e-12)) return {};
  const glm::dvec2 centre = (la * a + lb * b + lc * c) / perimeter;
  const double scale = 1.0 + kEmitterRegionGrowth / inradius;
  return clipToPixel({centre + scale * (a - centre), centre + scale * (b - centre), centre + scale * (c - centre)}, x, y);
}
}  // namespace

double polygonAreaInPixel(const std::vector<glm::dvec2>& corners, int x, int y) {
  const std::vector<glm::dvec2> p = clipToPixel(corners, x, y);
  double twice = 0.0;
  for (size_t i = 2; i < p.size(); ++i) twice += twiceArea(p[0], p[i - 1], p[i]);
  return 0.5 * twice;
}

EmitterPixelLists emitterPixelTriangles(const shared::GpuCamera& cam, int width, int height,
                                        const std::vector<glm::vec3>& vertices) {
  const size_t n = size_t(width) * size_t(height);
  EmitterPixelLists lists;
  lists.begin.assign(n + 1, 0u);
  // The pieces as the triangles give them, with their pixels; then laid out by pixel (a counting
  // sort, stable: by increasing triangle within a pixel).
  std::vector<EmitterPiece> found;
  std::vector<uint32_t> pixelOf;
  auto add = [&](uint32_t k, int x, int y, const EmitterProjection& p) {
    const std::vector<glm::dvec2> r = emitterRegion(p, x, y);
    for (size_t i = 2; i < r.size(); ++i) {
      const double area = 0.5 * twiceArea(r[0], r[i - 1], r[i]);
      if (!(area > 0.0)) continue;
      found.push_back({k, float(area), glm::vec2(r[0]), glm::vec2(r[i - 1]), glm::vec2(r[i])});
      pixelOf.push_back(uint32_t(size_t(y) * size_t(width) + size_t(x)));
    }
  };
  if (!forEachEmitterPixel(cam, width, height, vertices, add)) {
    // (not a number: every triangle in every pixel, each drawn on the whole of it)
    EmitterProjection whole;
    whole.clipped = true;
    found.clear();
    pixelOf.clear();
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x)
        for (uint32_t k = 0; k < uint32_t(vertices.size() / 3); ++k) add(k, x, y, whole);
  }
  for (uint32_t i : pixelOf) ++lists.begin[size_t(i) + 1];
  for (size_t i = 0; i < n; ++i) lists.begin[i + 1] += lists.begin[i];
  lists.pieces.resize(found.size());
  std::vector<uint32_t> next(lists.begin.begin(), lists.begin.end() - 1);
  for (size_t j = 0; j < found.size(); ++j) lists.pieces[next[pixelOf[j]]++] = found[j];
  return lists;
}

std::vector<uint32_t> emitterPixelMask(const std::vector<uint64_t>& rects) {
  std::vector<uint32_t> mask((rects.size() + 31) / 32, 0u);
  for (size_t i = 0; i < rects.size(); ++i)
    if (rects[i] != kNoEmitterRect) mask[i / 32] |= 1u << (i % 32);
  return mask;
}

}  // namespace plume
