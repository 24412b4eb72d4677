// plume-volgen: makes the volumes bundled with Plume (volumes/README.md documents each one).
// Everything here is deterministic: no unseeded randomness, no dependence on thread order (parallel
// loops only write their own cells), and the VDB files' random archive UUID is replaced by one
// derived from the file's contents, so the same command writes byte-identical files on every run.
#pragma once

#include <openvdb/openvdb.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace volgen {

// --- Writing VDB files (vdb_io.cpp) ------------------------------------------------------------
// Writes `grids` with BLOSC compression (optionally as half floats) and a content-derived UUID.
// Throws std::runtime_error on failure.
void writeVdb(const std::string& path, const openvdb::GridPtrVec& grids, bool halfFloat = false);
// The same bytes as writeVdb would write, in memory.
std::string vdbBytes(const openvdb::GridPtrVec& grids, bool halfFloat = false);
// Writes raw bytes to a file (throws on failure).
void writeBytes(const std::string& path, const std::string& bytes);
// A linear transform: world = voxelSize * index + translation.
openvdb::math::Transform::Ptr linearTransform(double voxelSize, const openvdb::Vec3d& translation);
// "name: 12345 active voxels, 3 tiles, values [a, b], 12.3 kB" for the log.
std::string describe(const std::string& path, const openvdb::FloatGrid& grid);

// --- Deterministic noise (noise.cpp) -----------------------------------------------------------
uint32_t hash32(uint32_t a, uint32_t b = 0, uint32_t c = 0, uint32_t d = 0);
float hashUnit(uint32_t a, uint32_t b = 0, uint32_t c = 0, uint32_t d = 0);  // in [0, 1)
// Smooth value noise in [-1, 1] on an integer lattice (period-free), and its fractal sum.
float valueNoise(float x, float y, float z, uint32_t seed);
float fbm(float x, float y, float z, int octaves, uint32_t seed);  // roughly in [-1, 1]

// --- Subcommands -------------------------------------------------------------------------------
struct SmokeParams {
  std::string out = "volumes/smoke";
  int frames = 24;
  int res = 64;            // cells per axis; the domain is always 2 world units wide
  int substeps = 2;        // solver steps per frame
  int preroll = 12;        // frames simulated before frame 1
  int pressureIters = 80;  // red-black SOR sweeps per step
  float fps = 24.0f;
  float buoyancy = 4.0f;   // world units/s² per unit temperature
  float weight = 0.25f;    // world units/s² per unit density (pulls smoke down)
  float cooling = 0.9f;    // 1/s, temperature decays as exp(-cooling t)
  float vorticity = 10.0f; // vorticity confinement epsilon (Fedkiw et al. 2001 eq. 11, h = 1 cell)
  uint32_t seed = 7;
  bool halfFloat = false;
  // Fire (`plume-volgen fire`): files fire_NNNN.vdb with the grids density, temperature (the
  // solver's T in [0, 1]) and flame (smoothstep of T from flameLow to flameHigh), the source
  // injecting sourceDensity times the smoke's density.
  bool fire = false;
  float sourceDensity = 1.0f;
  float sourceTemperature = 1.0f;  // the source sets T = min(1, sourceTemperature * strength)
  float flameLow = 0.45f, flameHigh = 0.9f;
};
int runSmoke(const SmokeParams& p);
// The defaults of `plume-volgen fire` (volumes/README.md).
SmokeParams fireDefaults();

// An analytic HDR sky with a sun disk as a lat-long EXR (sky.cpp documents the model).
struct SkyParams {
  std::string out = "volumes/sky/sky.exr";
  int height = 256;                                    // the map is 2 * height x height
  std::array<double, 3> sunDir{0.5, 1.0, 0.35};        // towards the sun (world, up = +Y)
  double sunRadiusDeg = 2.0;                           // angular radius of the disk
  double sunIrradiance = 3.0;                          // W/m² perpendicular to the sun (per channel)
  std::array<double, 3> zenith{0.05, 0.08, 0.16};
  std::array<double, 3> horizon{0.16, 0.17, 0.19};
  std::array<double, 3> ground{0.05, 0.045, 0.04};
  std::array<double, 3> glow{0.25, 0.22, 0.16};        // around the sun
  double glowWidth = 0.25;                             // radians
};
int runSky(const SkyParams& p);
// Writes RGB half-float texels (row-major, top row first) as a ZIP-compressed EXR.
void writeSkyExr(const std::string& path, int width, int height, const std::vector<float>& rgb);

// A sphere as a Wavefront OBJ with per-vertex normals (mesh.cpp), for the bundled surface scenes.
struct MeshParams {
  std::string out = "volumes/smoke/sphere.obj";
  std::array<double, 3> centre{0.7, 0.25, -0.25};
  double radius = 0.25;
  int rings = 24;
  int segments = 48;
};
int runMesh(const MeshParams& p);

// The many-lights scene's city of lamps around the smoke (city.cpp): buildings, street lamps and
// lit windows as OBJ files in `out`, exactly `quads` emissive quads; deterministic in `seed`.
struct CityParams {
  std::string out = "volumes/city";
  int quads = 4000;         // emissive quads: street lamps and lit windows together
  uint32_t seed = 12;
  double radius = 3.6;      // the city's extent around the origin, world units
  double plaza = 0.7;       // open around the smoke's source
  double block = 0.3;       // street grid pitch
  double street = 0.09;     // street width
  double maxHeight = 0.45;  // the tallest buildings (next to the plaza)
  double lampShare = 0.25;  // of the quads, street lamps (the rest: windows)
  double coolShare = 0.3;   // of the buildings, those with cool light
};
int runCity(const CityParams& p);

int runProcedural(const std::string& outDir);
int runBadInputs(const std::string& outDir);

// An image of a grid for eyeballing: single scattering of a sun from `toLight`, orthographic
// camera looking along -z (or -x), written as binary PGM.
struct PreviewParams {
  std::string in, out, grid = "density";
  float densityScale = 10.0f;
  char axis = 'z';
  int box = 0;  // > 0: show index box [0, box-1]³ instead of the active bounding box
};
int runPreview(const PreviewParams& p);

}  // namespace volgen
