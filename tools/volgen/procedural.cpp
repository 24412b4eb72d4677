// `plume-volgen procedural`: small analytic test grids (volumes/README.md gives their formulas).
//   sphere.vdb  fog sphere from a level set: narrow-band voxels plus an interior of active tiles
//   cloud.vdb   fBm-displaced, flat-bottomed ellipsoid with fBm-modulated density
//   slab.vdb    density 1 in a box of dense active voxels (no tiles)
//   ramp.vdb    density = world x on a box of voxels, exact under trilinear interpolation
#include "volgen.h"

#include <openvdb/tools/LevelSetSphere.h>
#include <openvdb/tools/LevelSetUtil.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>

namespace volgen {
namespace {

constexpr double kVoxel = 1.0 / 32.0;  // world units, every procedural grid

openvdb::FloatGrid::Ptr newDensity(const openvdb::Vec3d& translation) {
  auto grid = openvdb::FloatGrid::create(0.0f);
  grid->setName("density");
  grid->setGridClass(openvdb::GRID_FOG_VOLUME);
  grid->setTransform(linearTransform(kVoxel, translation));
  return grid;
}

// Sets voxel values from f(i, j, k) over an index box; values below `keepAbove` stay inactive.
void fill(openvdb::FloatGrid& grid, const openvdb::CoordBBox& box, float keepAbove,
          const std::function<float(int, int, int)>& f) {
  auto acc = grid.getAccessor();
  for (int k = box.min().z(); k <= box.max().z(); ++k)
    for (int j = box.min().y(); j <= box.max().y(); ++j)
      for (int i = box.min().x(); i <= box.max().x(); ++i) {
        float v = f(i, j, k);
        if (v > keepAbove) acc.setValue(openvdb::Coord(i, j, k), v);
      }
}

openvdb::FloatGrid::Ptr makeSphere() {
  // Level set of a sphere of radius 0.75, 3 voxels of narrow band each side; sdfToFogVolume maps
  // it to 0 outside, -sdf/(3 voxels) in the inner band and 1 inside, where the interior becomes
  // active tiles. Made around index (32,32,32), then moved so that index is the world origin
  // (positive indices keep the file small: one top-level node instead of eight).
  auto grid = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(0.75f, openvdb::Vec3f(1.0f), float(kVoxel),
                                                                       3.0f, /*threaded=*/false);
  openvdb::tools::sdfToFogVolume(*grid);
  grid->transform().postTranslate(openvdb::Vec3d(-1.0));
  grid->setName("density");
  return grid;
}

openvdb::FloatGrid::Ptr makeCloud() {
  auto grid = newDensity(openvdb::Vec3d(-1.0));  // world = h*index - 1: index (32,32,32) = origin
  const uint32_t seed = 2024;
  fill(*grid, openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(63)), 1e-4f, [&](int i, int j, int k) {
    float x = float(i * kVoxel - 1), y = float(j * kVoxel - 1), z = float(k * kVoxel - 1);
    float r = std::sqrt(x * x + 1.8f * y * y + z * z);            // ellipsoid, flatter in y
    float radius = 0.62f * (1.0f + 0.45f * fbm(3 * x, 3 * y, 3 * z, 5, seed));
    float shape = std::clamp((radius - r) / 0.1f, 0.0f, 1.0f);   // soft edge, 0.1 units wide
    float base = std::clamp((y + 0.3f) / 0.08f, 0.0f, 1.0f);      // flat bottom at y = -0.3
    float detail = 0.5f + 0.5f * fbm(7 * x + 3.1f, 7 * y, 7 * z, 4, seed + 99);
    return shape * base * std::clamp(0.25f + 0.9f * detail, 0.0f, 1.0f);
  });
  return grid;
}

openvdb::FloatGrid::Ptr makeSlab() {
  // Voxel (i,j,k) centre at world (h(i+0.5) - 0.5, h(j+0.5) - 0.25, h(k+0.5) - 0.5): voxels i,k
  // in [0,31], j in [0,15] cover the world box [-0.5,0.5]×[-0.25,0.25]×[-0.5,0.5].
  auto grid = newDensity(openvdb::Vec3d(0.5 * kVoxel - 0.5, 0.5 * kVoxel - 0.25, 0.5 * kVoxel - 0.5));
  fill(*grid, openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(31, 15, 31)), 0.0f,
       [](int, int, int) { return 1.0f; });
  return grid;
}

openvdb::FloatGrid::Ptr makeRamp() {
  // Voxels i,j,k in [0,31], value (i+0.5)/32 = the world x of the voxel centre; the voxels cover
  // the world box [0,1]³.
  auto grid = newDensity(openvdb::Vec3d(0.5 * kVoxel));
  fill(*grid, openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(31)), 0.0f,
       [](int i, int, int) { return (float(i) + 0.5f) / 32.0f; });
  return grid;
}

}  // namespace

int runProcedural(const std::string& outDir) {
  namespace fs = std::filesystem;
  fs::create_directories(outDir);
  const std::pair<const char*, openvdb::FloatGrid::Ptr> grids[] = {
      {"sphere.vdb", makeSphere()}, {"cloud.vdb", makeCloud()}, {"slab.vdb", makeSlab()}, {"ramp.vdb", makeRamp()}};
  for (const auto& [name, grid] : grids) {
    std::string path = (fs::path(outDir) / name).string();
    writeVdb(path, {grid});
    std::printf("%s\n", describe(path, *grid).c_str());
  }
  return 0;
}

}  // namespace volgen
