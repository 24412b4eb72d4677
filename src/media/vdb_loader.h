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
  uint64_t clampedValues = 0;    // values clamped by clampOpticalDepth (when the caller ran it)
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

// Optical depth across one voxel (its shortest side) above which a voxel's value is clamped.
// A voxel at the bound transmits e^-128 across it, below the smallest float (1.4e-45): opaque
// before and after; what moves is where, inside the trilinear cell next to it, the medium turns
// opaque (a linear ramp from 0 to the bound reaches optical depth 1 at sqrt(2/128) ~ 1/8 of the
// cell). It bounds every estimator's majorant, so tracking through a cell with a huge value next
// to a thin one takes ~128 steps per voxel instead of the value's optical depth (1e30 per unit:
// unbounded). Real media stay far below it (dense clouds: 1-30 per voxel; the suite's density
// x300 cloud: 75).
constexpr double kMaxVoxelOpticalDepth = 128.0;

// The largest grid value a medium with this density scale keeps: kMaxVoxelOpticalDepth /
// (densityScale * shortest voxel side); infinity for densityScale <= 0.
double maxMediumValue(const openvdb::FloatGrid& grid, double densityScale);

// Clamps active values (voxels and tiles) above maxMediumValue(grid, densityScale) to it and
// returns the number of clamped voxels (a tile counts its voxels). Every estimator renders the
// clamped grid: the GPU bake (render/volume_source.cpp) and the CPU reference
// (app/cmd_reference.cpp) call it after loading, with a warning when it clamps. Parallel.
uint64_t clampOpticalDepth(openvdb::FloatGrid& grid, double densityScale);
// The warning both callers print: "PATH: N values above B (optical depth 128 per voxel ...) clamped to it".
void warnClamped(const LoadedGrid& grid, double densityScale);

}  // namespace plume
