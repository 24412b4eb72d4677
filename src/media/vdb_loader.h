// OpenVDB loading (DESIGN §2, §3): grids chosen by name, float/double/half converted to float,
// the grid's linear transform kept (frustum or non-linear maps refused), active tiles kept as
// tiles, NaN/Inf/negative values replaced by 0 and counted. Every failure is an InputError
// naming the file (and the grid), e.g. "smoke.vdb: no grid named \"dens\" (grids: density, flame)".
// An empty grid is a valid, empty medium.
#pragma once

#include <openvdb/openvdb.h>

#include <cstdint>
#include <string>
#include <vector>

namespace plume {

struct GridSummary {
  std::string name;
  std::string type;            // "float", "double", "half", "vec3s", ...
  openvdb::Vec3d voxelSize{0.0};
  openvdb::CoordBBox indexBounds;    // active bounds (empty for an empty grid)
  openvdb::BBoxd worldBounds;        // of the active index bounds' corners
  uint64_t activeVoxels = 0;         // includes voxels covered by active tiles
  uint64_t activeTiles = 0;
  float minValue = 0, maxValue = 0;  // over active values (scalar grids only)
  bool linear = true;                // transform is an affine map
};

struct LoadedGrid {
  openvdb::FloatGrid::Ptr grid;  // never null; sanitised; linear transform
  std::string path;
  std::string name;
  uint64_t replacedValues = 0;   // NaN, Inf and negative values set to 0
};

// Initialises OpenVDB once (thread-safe); every function below calls it.
void initOpenVdb();

// Summaries of every grid in a file (metadata and statistics); throws InputError.
std::vector<GridSummary> inspectVdb(const std::string& path);

// Loads one scalar grid as float. Throws InputError for a missing or corrupt file, a missing
// grid (the message lists the grids that exist), a non-scalar grid, a non-linear transform or
// a non-zero background.
LoadedGrid loadFloatGrid(const std::string& path, const std::string& gridName);

// The sanitising step of loadFloatGrid, for grids built in code (tests, tools): active values
// (voxels and tiles) that are NaN, Inf or negative become 0, every inactive value becomes the
// background 0 (so that samplers reading inactive voxels see 0, DESIGN §2). Returns the number of
// replaced active *voxels* (a replaced tile counts as the voxels it covers). Parallel.
uint64_t sanitizeGrid(openvdb::FloatGrid& grid);

}  // namespace plume
