// Small analytic OpenVDB grids built in code for the tests (no files needed).
#pragma once

#include <openvdb/openvdb.h>

namespace plume::test {

// Voxels [0, n-1]^3 set to `value` (dense, active voxels), uniform voxel size, no translation.
openvdb::FloatGrid::Ptr makeBoxGrid(int n, double voxelSize, float value = 1.0f);
// Value i/(n-1) at x-index i for i in [0, n-1] (any y, z in [0, n-1]): trilinear reproduces
// d(x) = x/(n-1) exactly inside [0, n-1]^3.
openvdb::FloatGrid::Ptr makeRampGrid(int n, double voxelSize);
// Deterministic smooth noise cloud in [0, n-1]^3, values in [0, 1], zero near the border.
openvdb::FloatGrid::Ptr makeNoiseGrid(int n, double voxelSize, unsigned seed = 1);

}  // namespace plume::test
