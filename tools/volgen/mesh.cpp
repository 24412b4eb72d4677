// `plume-volgen mesh`: the OBJ meshes bundled beside the volumes (volumes/README.md), written as
// text by hand so that the generator needs no geometry library: a latitude/longitude sphere with
// per-vertex normals (`vn`, smooth shading), every face counter-clockwise seen from outside
// (DESIGN §2: the front side). Fixed-precision output, so the same command writes the same bytes.
#include "volgen.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace volgen {

int runMesh(const MeshParams& p) {
  if (p.rings < 2 || p.segments < 3 || !(p.radius > 0.0))
    throw std::runtime_error("mesh: needs rings >= 2, segments >= 3, radius > 0");
  const std::filesystem::path out(p.out);
  if (out.has_parent_path()) std::filesystem::create_directories(out.parent_path());
  FILE* f = std::fopen(p.out.c_str(), "w");
  if (!f) throw std::runtime_error("cannot write " + p.out);
  std::fprintf(f, "# plume-volgen mesh: sphere, centre (%g, %g, %g), radius %g, %d rings x %d segments\no sphere\n",
               p.centre[0], p.centre[1], p.centre[2], p.radius, p.rings, p.segments);
  // Vertices: the two poles, then rings 1 .. rings-1 from the top, `segments` each.
  const double pi = 3.14159265358979323846;
  auto vertex = [&](double nx, double ny, double nz) {
    std::fprintf(f, "v %.5f %.5f %.5f\n", p.centre[0] + p.radius * nx, p.centre[1] + p.radius * ny,
                 p.centre[2] + p.radius * nz);
    std::fprintf(f, "vn %.5f %.5f %.5f\n", nx, ny, nz);
  };
  vertex(0, 1, 0);
  vertex(0, -1, 0);
  for (int r = 1; r < p.rings; ++r) {
    const double theta = pi * r / p.rings;
    for (int s = 0; s < p.segments; ++s) {
      const double phi = 2.0 * pi * s / p.segments;
      vertex(std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi));
    }
  }
  // OBJ indices from 1; position and normal share the index.
  auto at = [&](int ring, int s) { return 3 + (ring - 1) * p.segments + (s % p.segments); };
  auto face = [&](int a, int b, int c) { std::fprintf(f, "f %d//%d %d//%d %d//%d\n", a, a, b, b, c, c); };
  for (int s = 0; s < p.segments; ++s) {
    face(1, at(1, s), at(1, s + 1));  // phi grows counter-clockwise seen from above (+Y)
    for (int r = 1; r + 1 < p.rings; ++r) {
      face(at(r, s), at(r + 1, s), at(r + 1, s + 1));
      face(at(r, s), at(r + 1, s + 1), at(r, s + 1));
    }
    face(2, at(p.rings - 1, s + 1), at(p.rings - 1, s));
  }
  const bool ok = std::ferror(f) == 0;
  if (std::fclose(f) != 0 || !ok) throw std::runtime_error("cannot write " + p.out);
  std::printf("%s: %d vertices, %d triangles\n", p.out.c_str(), 2 + (p.rings - 1) * p.segments,
              2 * p.segments * (p.rings - 1));
  return 0;
}

}  // namespace volgen
