// A small deterministic stable-fluids smoke solver (Stam 1999; Fedkiw, Stam & Jensen 2001) on a
// MAC grid of res³ cells spanning the world box [-1,1]×[0,2]×[-1,1] (y up). Per step:
//   1. source: a noisy, pulsing ball near the floor sets density, temperature and upward velocity;
//   2. advection of velocity, density and temperature: MacCormack (Selle et al. 2008) with RK2
//      back-traces and min/max clamping (density and temperature stay in [0, 1]);
//   3. forces: buoyancy (Fedkiw et al. eq. 8: a_y = buoyancy*T - weight*d) and vorticity
//      confinement (eq. 9-11, with h = 1 cell);
//   4. pressure projection: red-black SOR on the 7-point Laplacian; walls on the sides and the
//      floor (zero normal velocity), an open top (pressure 0 above the domain).
// Parallel loops write only their own cells, so the result does not depend on thread order.
#include "volgen.h"

#include <openvdb/tools/Prune.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace volgen {
namespace {

using Vec3 = openvdb::Vec3f;
constexpr float kPruneBelow = 1e-4f;  // density below this is written as inactive background 0
constexpr float kDomainWidth = 2.0f;  // world units
using Clock = std::chrono::steady_clock;

template <typename F>
void parallelSlices(int nz, F&& f) {
  tbb::parallel_for(tbb::blocked_range<int>(0, nz), [&](const tbb::blocked_range<int>& r) {
    for (int k = r.begin(); k != r.end(); ++k) f(k);
  });
}

// A scalar field sampled at `offset + (i,j,k)` in grid space (cell (i,j,k) spans [i,i+1]×...).
struct Field {
  int nx = 0, ny = 0, nz = 0;
  Vec3 offset{0.0f};
  std::vector<float> a;

  Field() = default;
  Field(int x, int y, int z, Vec3 off) : nx(x), ny(y), nz(z), offset(off), a(size_t(x) * y * z, 0.0f) {}
  size_t idx(int i, int j, int k) const { return (size_t(k) * ny + j) * nx + i; }
  float& operator()(int i, int j, int k) { return a[idx(i, j, k)]; }
  float operator()(int i, int j, int k) const { return a[idx(i, j, k)]; }
  Vec3 pos(int i, int j, int k) const { return Vec3(float(i), float(j), float(k)) + offset; }

  // Lattice cell containing grid-space point p (clamped) and the weights inside it.
  void locate(const Vec3& p, int c[3], float t[3]) const {
    const int n[3] = {nx, ny, nz};
    for (int a = 0; a < 3; ++a) {
      float x = std::clamp(p[a] - offset[a], 0.0f, float(n[a] - 1));
      c[a] = std::min(int(x), n[a] - 2);
      t[a] = x - float(c[a]);
    }
  }
  float sample(const Vec3& p) const {
    int c[3];
    float t[3];
    locate(p, c, t);
    auto lerp = [](float a, float b, float s) { return a + (b - a) * s; };
    const float* q = &a[idx(c[0], c[1], c[2])];
    const size_t sy = size_t(nx), sz = size_t(nx) * ny;
    float x00 = lerp(q[0], q[1], t[0]), x10 = lerp(q[sy], q[sy + 1], t[0]);
    float x01 = lerp(q[sz], q[sz + 1], t[0]), x11 = lerp(q[sz + sy], q[sz + sy + 1], t[0]);
    return lerp(lerp(x00, x10, t[1]), lerp(x01, x11, t[1]), t[2]);
  }
  void minMax(const Vec3& p, float& lo, float& hi) const {
    int c[3];
    float t[3];
    locate(p, c, t);
    lo = hi = (*this)(c[0], c[1], c[2]);
    for (int d = 1; d < 8; ++d) {
      float v = (*this)(c[0] + (d & 1), c[1] + ((d >> 1) & 1), c[2] + (d >> 2));
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
};

class SmokeSolver {
 public:
  explicit SmokeSolver(const SmokeParams& prm)
      : prm_(prm), n_(prm.res), h_(kDomainWidth / float(prm.res)),
        u_(n_ + 1, n_, n_, Vec3(0, 0.5f, 0.5f)), v_(n_, n_ + 1, n_, Vec3(0.5f, 0, 0.5f)),
        w_(n_, n_, n_ + 1, Vec3(0.5f, 0.5f, 0)), d_(n_, n_, n_, Vec3(0.5f)), T_(d_), p_(d_) {}

  void step(float dt, int index) {
    auto t0 = Clock::now();
    addSource(dt, index);
    advect(dt);
    const float cool = std::exp(-prm_.cooling * dt);
    for (float& t : T_.a) t *= cool;
    auto t1 = Clock::now();
    addBuoyancy(dt);
    addVorticityConfinement(dt);
    enforceWalls();
    auto t2 = Clock::now();
    project();
    auto t3 = Clock::now();
    secs_[0] += std::chrono::duration<double>(t1 - t0).count();
    secs_[1] += std::chrono::duration<double>(t2 - t1).count();
    secs_[2] += std::chrono::duration<double>(t3 - t2).count();
  }
  // Seconds spent in advection (with sources), forces and projection.
  const double* timings() const { return secs_; }

  // Density as a sparse FloatGrid: voxel (i,j,k) = cell (i,j,k), centred in world at
  // (-1 + (i+0.5)h, (j+0.5)h, -1 + (k+0.5)h).
  openvdb::FloatGrid::Ptr densityGrid() const {
    return grid("density", [&](int i, int j, int k) { return std::min(d_(i, j, k), 1.0f); });
  }
  // The solver's temperature T in [0, 1] (plume-volgen fire).
  openvdb::FloatGrid::Ptr temperatureGrid() const {
    return grid("temperature", [&](int i, int j, int k) { return std::min(T_(i, j, k), 1.0f); });
  }
  // Flames where the gas is hot: smoothstep(flameLow, flameHigh, T) (plume-volgen fire).
  openvdb::FloatGrid::Ptr flameGrid() const {
    return grid("flame", [&](int i, int j, int k) {
      float x = std::clamp((T_(i, j, k) - prm_.flameLow) / (prm_.flameHigh - prm_.flameLow), 0.0f, 1.0f);
      return x * x * (3 - 2 * x);
    });
  }

  float maxSpeedWorld() const {
    float m = 0;
    for (int k = 0; k < n_; ++k)
      for (int j = 0; j < n_; ++j)
        for (int i = 0; i < n_; ++i) m = std::max(m, velocity(d_.pos(i, j, k)).length());
    return m * h_;
  }

 private:
  Vec3 velocity(const Vec3& p) const { return Vec3(u_.sample(p), v_.sample(p), w_.sample(p)); }

  // Grid-space point that flows to p in time dt (RK2 midpoint), clamped to the domain.
  Vec3 backTrace(const Vec3& p, float dt) const {
    Vec3 mid = p - 0.5f * dt * velocity(p);
    Vec3 q = p - dt * velocity(mid);
    for (int a = 0; a < 3; ++a) q[a] = std::clamp(q[a], 0.0f, float(n_));
    return q;
  }

  void addSource(float dt, int index) {
    const float t = float(index) * dt;
    const float pulse = 0.8f + 0.2f * std::sin(2.0f * float(M_PI) * 1.3f * t);
    const Vec3 c(0.5f * n_, 0.11f * n_, 0.5f * n_);  // world (0, 0.22, 0)
    const float r = 0.22f / h_;                       // world radius 0.22
    const float inflow = 0.8f / h_;                   // world 0.8 units/s upwards
    const float jitter = 0.3f / h_;                   // up to 0.3 units/s sideways
    const float ns = 8.0f / float(n_);                // noise features ~ 1/8 of the domain
    parallelSlices(n_, [&](int k) {
      for (int j = 0; j < n_ / 4; ++j)
        for (int i = 0; i < n_; ++i) {
          Vec3 x = d_.pos(i, j, k);
          float s = 1.0f - (x - c).length() / r;
          if (s <= 0) continue;
          s = s * s * (3 - 2 * s);
          float noise = 0.5f + 0.5f * valueNoise(x[0] * ns * 2, x[1] * ns * 2 - 6 * t, x[2] * ns * 2, prm_.seed);
          float e = std::min(1.0f, 1.6f * s) * pulse * (0.55f + 0.45f * noise);
          d_(i, j, k) = std::max(d_(i, j, k), prm_.sourceDensity * e);
          T_(i, j, k) = std::max(T_(i, j, k), std::min(1.0f, prm_.sourceTemperature * e));
          v_(i, j + 1, k) = std::max(v_(i, j + 1, k), inflow * s * (0.5f + noise));
          // A swirling horizontal kick that changes over time breaks the symmetry.
          float jx = valueNoise(x[0] * ns, x[1] * ns - 4 * t, x[2] * ns, prm_.seed + 1);
          float jz = valueNoise(x[0] * ns, x[1] * ns - 4 * t, x[2] * ns, prm_.seed + 2);
          u_(i, j, k) += s * jitter * jx, w_(i, j, k) += s * jitter * jz;
        }
    });
  }

  // A sparse FloatGrid of value(i,j,k): voxel (i,j,k) = cell (i,j,k), centred in world at
  // (-1 + (i+0.5)h, (j+0.5)h, -1 + (k+0.5)h); values below kPruneBelow stay inactive.
  template <typename Value>
  openvdb::FloatGrid::Ptr grid(const char* name, Value&& value) const {
    auto grid = openvdb::FloatGrid::create(0.0f);
    grid->setName(name);
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    grid->setTransform(linearTransform(h_, openvdb::Vec3d(-1.0 + 0.5 * h_, 0.5 * h_, -1.0 + 0.5 * h_)));
    auto acc = grid->getAccessor();
    for (int k = 0; k < n_; ++k)
      for (int j = 0; j < n_; ++j)
        for (int i = 0; i < n_; ++i) {
          float v = value(i, j, k);
          if (v >= kPruneBelow) acc.setValue(openvdb::Coord(i, j, k), v);
        }
    openvdb::tools::prune(grid->tree());
    return grid;
  }

  // Advects every field with the current (old) velocity, then replaces them all.
  void advect(float dt) {
    std::vector<Vec3> from, to;
    tracePositions(d_, dt, from, to);  // d and T share their lattice
    Field d = macCormack(d_, from, to), T = macCormack(T_, from, to);
    Field u = advected(u_, dt), v = advected(v_, dt), w = advected(w_, dt);
    d_ = std::move(d), T_ = std::move(T), u_ = std::move(u), v_ = std::move(v), w_ = std::move(w);
  }

  // Velocity uses plain semi-Lagrangian advection: cheaper, and vorticity confinement restores
  // the swirl that its smoothing removes.
  Field advected(const Field& f, float dt) const {
    Field out = f;
    parallelSlices(f.nz, [&](int k) {
      for (int j = 0; j < f.ny; ++j)
        for (int i = 0; i < f.nx; ++i) out(i, j, k) = f.sample(backTrace(f.pos(i, j, k), dt));
    });
    return out;
  }

  // For each sample of the lattice: where it comes from (back-trace over dt) and where it goes.
  void tracePositions(const Field& lattice, float dt, std::vector<Vec3>& from, std::vector<Vec3>& to) const {
    from.resize(lattice.a.size());
    to.resize(lattice.a.size());
    parallelSlices(lattice.nz, [&](int k) {
      for (int j = 0; j < lattice.ny; ++j)
        for (int i = 0; i < lattice.nx; ++i) {
          size_t c = lattice.idx(i, j, k);
          from[c] = backTrace(lattice.pos(i, j, k), dt);
          to[c] = backTrace(lattice.pos(i, j, k), -dt);
        }
    });
  }

  // MacCormack (Selle et al. 2008): a forward semi-Lagrangian step, a backward one to estimate
  // its error, half the error added back, and the result clamped to the values around the
  // back-traced point (falling back to the plain semi-Lagrangian value), so no new extrema.
  static Field macCormack(const Field& f, const std::vector<Vec3>& from, const std::vector<Vec3>& to) {
    Field fwd = f, out = f;
    const size_t slice = size_t(f.nx) * f.ny;
    parallelSlices(f.nz, [&](int k) {
      for (size_t c = slice * k, e = c + slice; c < e; ++c) fwd.a[c] = f.sample(from[c]);
    });
    parallelSlices(f.nz, [&](int k) {
      for (size_t c = slice * k, e = c + slice; c < e; ++c) {
        float lo, hi;
        f.minMax(from[c], lo, hi);
        float v = fwd.a[c] + 0.5f * (f.a[c] - fwd.sample(to[c]));
        out.a[c] = (v < lo || v > hi) ? fwd.a[c] : v;
      }
    });
    return out;
  }

  void addBuoyancy(float dt) {
    const float b = prm_.buoyancy / h_, wgt = prm_.weight / h_;  // cells/s² per unit T or d
    parallelSlices(n_, [&](int k) {
      for (int j = 1; j <= n_; ++j)
        for (int i = 0; i < n_; ++i) {
          int jb = j - 1, ja = std::min(j, n_ - 1);
          float T = 0.5f * (T_(i, jb, k) + T_(i, ja, k)), d = 0.5f * (d_(i, jb, k) + d_(i, ja, k));
          v_(i, j, k) += dt * (b * T - wgt * d);
        }
    });
  }

  void addVorticityConfinement(float dt) {
    if (prm_.vorticity <= 0) return;
    Field cx = d_, cy = d_, cz = d_, mag = d_;
    auto uc = [&](int i, int j, int k) {  // cell-centred velocity, indices clamped
      i = std::clamp(i, 0, n_ - 1), j = std::clamp(j, 0, n_ - 1), k = std::clamp(k, 0, n_ - 1);
      return Vec3(0.5f * (u_(i, j, k) + u_(i + 1, j, k)), 0.5f * (v_(i, j, k) + v_(i, j + 1, k)),
                  0.5f * (w_(i, j, k) + w_(i, j, k + 1)));
    };
    parallelSlices(n_, [&](int k) {
      for (int j = 0; j < n_; ++j)
        for (int i = 0; i < n_; ++i) {
          Vec3 dx = 0.5f * (uc(i + 1, j, k) - uc(i - 1, j, k)), dy = 0.5f * (uc(i, j + 1, k) - uc(i, j - 1, k)),
               dz = 0.5f * (uc(i, j, k + 1) - uc(i, j, k - 1));
          Vec3 curl(dy[2] - dz[1], dz[0] - dx[2], dx[1] - dy[0]);
          cx(i, j, k) = curl[0], cy(i, j, k) = curl[1], cz(i, j, k) = curl[2];
          mag(i, j, k) = curl.length();
        }
    });
    Field fx = d_, fy = d_, fz = d_;
    auto m = [&](int i, int j, int k) {
      return mag(std::clamp(i, 0, n_ - 1), std::clamp(j, 0, n_ - 1), std::clamp(k, 0, n_ - 1));
    };
    parallelSlices(n_, [&](int k) {
      for (int j = 0; j < n_; ++j)
        for (int i = 0; i < n_; ++i) {
          Vec3 g(0.5f * (m(i + 1, j, k) - m(i - 1, j, k)), 0.5f * (m(i, j + 1, k) - m(i, j - 1, k)),
                 0.5f * (m(i, j, k + 1) - m(i, j, k - 1)));
          Vec3 N = g / (g.length() + 1e-6f);
          Vec3 f = prm_.vorticity * N.cross(Vec3(cx(i, j, k), cy(i, j, k), cz(i, j, k)));
          fx(i, j, k) = f[0], fy(i, j, k) = f[1], fz(i, j, k) = f[2];
        }
    });
    parallelSlices(n_, [&](int k) {
      for (int j = 0; j < n_; ++j)
        for (int i = 1; i < n_; ++i) u_(i, j, k) += dt * 0.5f * (fx(i - 1, j, k) + fx(i, j, k));
      for (int j = 1; j < n_; ++j)
        for (int i = 0; i < n_; ++i) v_(i, j, k) += dt * 0.5f * (fy(i, j - 1, k) + fy(i, j, k));
      if (k > 0)
        for (int j = 0; j < n_; ++j)
          for (int i = 0; i < n_; ++i) w_(i, j, k) += dt * 0.5f * (fz(i, j, k - 1) + fz(i, j, k));
    });
  }

  void enforceWalls() {
    for (int k = 0; k < n_; ++k)
      for (int j = 0; j < n_; ++j) u_(0, j, k) = u_(n_, j, k) = 0;
    for (int k = 0; k < n_; ++k)
      for (int i = 0; i < n_; ++i) v_(i, 0, k) = 0;
    for (int j = 0; j < n_; ++j)
      for (int i = 0; i < n_; ++i) w_(i, j, 0) = w_(i, j, n_) = 0;
  }

  // Solves sum_nb (p_nb - p) = div u (p = 0 above the top) by red-black SOR, warm-started from
  // the previous step's pressure, then subtracts the pressure gradient from the face velocities.
  void project() {
    Field div = d_;
    parallelSlices(n_, [&](int k) {
      for (int j = 0; j < n_; ++j)
        for (int i = 0; i < n_; ++i)
          div(i, j, k) = u_(i + 1, j, k) - u_(i, j, k) + v_(i, j + 1, k) - v_(i, j, k) + w_(i, j, k + 1) - w_(i, j, k);
    });
    const float omega = 1.85f;
    for (int it = 0; it < prm_.pressureIters; ++it) {
      for (int colour = 0; colour < 2; ++colour) {
        parallelSlices(n_, [&](int k) {
          for (int j = 0; j < n_; ++j)
            for (int i = (j + k + colour) & 1; i < n_; i += 2) {
              float sum = 0, count = 0;
              if (i > 0) sum += p_(i - 1, j, k), count += 1;
              if (i < n_ - 1) sum += p_(i + 1, j, k), count += 1;
              if (j > 0) sum += p_(i, j - 1, k), count += 1;
              if (j < n_ - 1) sum += p_(i, j + 1, k);
              count += 1;  // above: a fluid cell or the open top (p = 0)
              if (k > 0) sum += p_(i, j, k - 1), count += 1;
              if (k < n_ - 1) sum += p_(i, j, k + 1), count += 1;
              float gs = (sum - div(i, j, k)) / count;
              p_(i, j, k) += omega * (gs - p_(i, j, k));
            }
        });
      }
    }
    parallelSlices(n_, [&](int k) {
      for (int j = 0; j < n_; ++j)
        for (int i = 1; i < n_; ++i) u_(i, j, k) -= p_(i, j, k) - p_(i - 1, j, k);
      for (int j = 1; j <= n_; ++j)
        for (int i = 0; i < n_; ++i) v_(i, j, k) -= (j < n_ ? p_(i, j, k) : 0.0f) - p_(i, j - 1, k);
      if (k > 0)
        for (int j = 0; j < n_; ++j)
          for (int i = 0; i < n_; ++i) w_(i, j, k) -= p_(i, j, k) - p_(i, j, k - 1);
    });
  }

  SmokeParams prm_;
  int n_;
  float h_;  // world units per cell
  Field u_, v_, w_, d_, T_, p_;
  double secs_[3] = {0, 0, 0};
};

}  // namespace

SmokeParams fireDefaults() {
  SmokeParams p;
  p.out = "volumes/fire";
  p.fire = true;
  p.buoyancy = 6.0f;       // hot gas rises faster
  p.cooling = 2.2f;        // and cools quickly: flames near the source, smoke above
  p.sourceDensity = 0.35f; // a fire makes less smoke than a smoke pot
  p.sourceTemperature = 2.0f;  // and its source burns at the top of the range
  p.halfFloat = true;      // 16-bit values: half the size in the repository
  p.vorticity = 12.0f;
  p.seed = 11;
  return p;
}

int runSmoke(const SmokeParams& prm) {
  namespace fs = std::filesystem;
  if (prm.res < 8 || prm.frames < 1 || prm.substeps < 1) {
    std::fprintf(stderr, "plume-volgen smoke: need --res >= 8, --frames >= 1, --substeps >= 1\n");
    return 2;
  }
  fs::create_directories(prm.out);
  auto start = std::chrono::steady_clock::now();
  SmokeSolver solver(prm);
  const float dt = 1.0f / (prm.fps * float(prm.substeps));
  int stepIndex = 0;
  for (int f = 1 - prm.preroll; f <= prm.frames; ++f) {
    for (int s = 0; s < prm.substeps; ++s) solver.step(dt, stepIndex++);
    if (f < 1) continue;
    char name[64];
    std::snprintf(name, sizeof name, prm.fire ? "fire_%04d.vdb" : "smoke_%04d.vdb", f);
    std::string path = (fs::path(prm.out) / name).string();
    auto grid = solver.densityGrid();
    openvdb::GridPtrVec grids{grid};
    if (prm.fire) {
      grids.push_back(solver.temperatureGrid());
      grids.push_back(solver.flameGrid());
    }
    writeVdb(path, grids, prm.halfFloat);
    std::printf("%s, max speed %.2f units/s\n", describe(path, *grid).c_str(), solver.maxSpeedWorld());
    for (size_t g = 1; g < grids.size(); ++g)
      std::printf("  %s\n", describe(path, static_cast<const openvdb::FloatGrid&>(*grids[g])).c_str());
  }
  double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double* t = solver.timings();
  std::printf("%s: %d frames (+%d pre-roll) at %d³, %d steps, %.1f s (advection %.1f s, forces %.1f s, "
              "pressure %.1f s)\n", prm.fire ? "fire" : "smoke", prm.frames, prm.preroll, prm.res, stepIndex, secs, t[0], t[1], t[2]);
  return 0;
}

}  // namespace volgen
