// plume-volgen: makes the volumes bundled with Plume (see volumes/README.md).
//   plume-volgen smoke --out volumes/smoke --frames 24 --res 64
//   plume-volgen fire --out volumes/fire --frames 24 --res 64
//   plume-volgen procedural --out volumes/procedural
//   plume-volgen sky --out volumes/sky/sky.exr
//   plume-volgen mesh --out volumes/smoke/sphere.obj
//   plume-volgen city --out volumes/city
//   plume-volgen badinputs --out tests/bad_inputs
//   plume-volgen preview FILE.vdb -o FILE.pgm
#include "volgen.h"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <functional>

int main(int argc, char** argv) {
  using namespace volgen;
  CLI::App app{"plume-volgen: deterministic generator of Plume's bundled OpenVDB volumes"};
  app.require_subcommand(1);
  std::function<int()> action;

  SmokeParams smoke;
  auto* sm = app.add_subcommand("smoke", "stable-fluids smoke plume, one density VDB per frame");
  sm->add_option("--out", smoke.out, "output folder")->capture_default_str();
  sm->add_option("--frames", smoke.frames, "frames to write")->capture_default_str();
  sm->add_option("--res", smoke.res, "cells per axis (domain is 2 world units wide)")->capture_default_str();
  sm->add_option("--substeps", smoke.substeps, "solver steps per frame")->capture_default_str();
  sm->add_option("--preroll", smoke.preroll, "frames simulated before frame 1")->capture_default_str();
  sm->add_option("--pressure-iters", smoke.pressureIters, "SOR sweeps per step")->capture_default_str();
  sm->add_option("--buoyancy", smoke.buoyancy, "units/s² per unit temperature")->capture_default_str();
  sm->add_option("--weight", smoke.weight, "units/s² per unit density")->capture_default_str();
  sm->add_option("--cooling", smoke.cooling, "temperature decay rate, 1/s")->capture_default_str();
  sm->add_option("--vorticity", smoke.vorticity, "vorticity confinement strength")->capture_default_str();
  sm->add_option("--seed", smoke.seed, "noise seed")->capture_default_str();
  sm->add_flag("--half,!--no-half", smoke.halfFloat, "store values as 16-bit floats")->capture_default_str();
  sm->callback([&] { action = [&] { return runSmoke(smoke); }; });

  SmokeParams fire = fireDefaults();
  auto* fi = app.add_subcommand("fire", "the smoke solver as a fire: density, temperature and flame grids per frame");
  fi->add_option("--out", fire.out, "output folder")->capture_default_str();
  fi->add_option("--frames", fire.frames, "frames to write")->capture_default_str();
  fi->add_option("--res", fire.res, "cells per axis (domain is 2 world units wide)")->capture_default_str();
  fi->add_option("--cooling", fire.cooling, "temperature decay rate, 1/s")->capture_default_str();
  fi->add_option("--buoyancy", fire.buoyancy, "units/s² per unit temperature")->capture_default_str();
  fi->add_option("--seed", fire.seed, "noise seed")->capture_default_str();
  fi->add_flag("--half,!--no-half", fire.halfFloat, "store values as 16-bit floats")->capture_default_str();
  fi->callback([&] { action = [&] { return runSmoke(fire); }; });

  std::string procOut = "volumes/procedural";
  auto* pr = app.add_subcommand("procedural", "sphere, cloud, slab and ramp test grids");
  pr->add_option("--out", procOut, "output folder")->capture_default_str();
  pr->callback([&] { action = [&] { return runProcedural(procOut); }; });

  SkyParams sky;
  auto* sk = app.add_subcommand("sky", "analytic HDR sky with a sun disk, lat-long EXR (DESIGN §2)");
  sk->add_option("--out", sky.out, "output .exr")->capture_default_str();
  sk->add_option("--height", sky.height, "rows (the map is twice as wide)")->capture_default_str();
  sk->add_option("--sun-dir", sky.sunDir, "direction towards the sun (world, y up)")->expected(3);
  sk->add_option("--sun-radius", sky.sunRadiusDeg, "angular radius of the sun disk, degrees")->capture_default_str();
  sk->add_option("--sun-irradiance", sky.sunIrradiance, "irradiance of the sun disk")->capture_default_str();
  sk->callback([&] { action = [&] { return runSky(sky); }; });

  MeshParams mesh;
  auto* me = app.add_subcommand("mesh", "a sphere with vertex normals as a Wavefront OBJ (the bundled surface scene's object)");
  me->add_option("--out", mesh.out, "output .obj")->capture_default_str();
  me->add_option("--centre", mesh.centre, "world centre")->expected(3);
  me->add_option("--radius", mesh.radius, "radius, world units")->capture_default_str();
  me->add_option("--rings", mesh.rings, "latitude bands")->capture_default_str();
  me->add_option("--segments", mesh.segments, "meridians")->capture_default_str();
  me->callback([&] { action = [&] { return runMesh(mesh); }; });

  CityParams city;
  auto* ci = app.add_subcommand("city", "the many-lights scene: a night city of emissive quads around the smoke (OBJ files)");
  ci->add_option("--out", city.out, "output folder")->capture_default_str();
  ci->add_option("--quads", city.quads, "emissive quads (street lamps + lit windows), exactly")->capture_default_str();
  ci->add_option("--seed", city.seed, "layout and lighting seed")->capture_default_str();
  ci->add_option("--radius", city.radius, "city radius around the origin, world units")->capture_default_str();
  ci->add_option("--plaza", city.plaza, "radius left open around the smoke")->capture_default_str();
  ci->add_option("--block", city.block, "street grid pitch")->capture_default_str();
  ci->add_option("--street", city.street, "street width")->capture_default_str();
  ci->add_option("--max-height", city.maxHeight, "height of the tallest buildings")->capture_default_str();
  ci->add_option("--lamp-share", city.lampShare, "share of the quads that are street lamps")->capture_default_str();
  ci->add_option("--cool-share", city.coolShare, "share of the buildings with cool window light")->capture_default_str();
  ci->callback([&] { action = [&] { return runCity(city); }; });

  std::string badOut = "tests/bad_inputs";
  auto* bi = app.add_subcommand("badinputs", "broken VDB files for tests/bad_inputs");
  bi->add_option("--out", badOut, "output folder")->capture_default_str();
  bi->callback([&] { action = [&] { return runBadInputs(badOut); }; });

  PreviewParams preview;
  auto* pv = app.add_subcommand("preview", "single-scattering preview image (PGM) of a grid");
  pv->add_option("file", preview.in, "VDB file")->required();
  pv->add_option("-o,--out", preview.out, "output .pgm")->required();
  pv->add_option("--grid", preview.grid, "grid name")->capture_default_str();
  pv->add_option("--density-scale", preview.densityScale, "sigma_t per unit density")->capture_default_str();
  pv->add_option("--axis", preview.axis, "view along -z (z) or -x (x)")->capture_default_str();
  pv->add_option("--box", preview.box, "show index box [0,N-1]³ (0: the active bounding box)");
  pv->callback([&] { action = [&] { return runPreview(preview); }; });

  CLI11_PARSE(app, argc, argv);
  try {
    openvdb::initialize();
    return action();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "plume-volgen: error: %s\n", e.what());
    return 1;
  }
}
