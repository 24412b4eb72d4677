#include "geometry/scene_mesh.h"

#include "core/error.h"
#include "core/log.h"
#include "geometry/obj.h"

#include <string>

namespace plume::geo {

SceneMesh loadSceneSurfaces(const Scene& scene) {
  SceneMesh out;
  for (size_t i = 0; i < scene.surfaces.size(); ++i) {
    const Surface& s = scene.surfaces[i];
    const std::string key = scene.path + ": surfaces[" + std::to_string(i) + "]";
    TriangleMesh mesh;
    size_t degenerate = 0;
    if (s.plane) {
      mesh = makePlane(s.plane->center, s.plane->normal, s.plane->size, key + ".plane");
    } else {
      ObjMesh obj = loadObj(s.obj);
      mesh = std::move(obj.mesh);
      degenerate = obj.stats.degenerate;
      if (degenerate > 0)
        logWarn(key + ".obj: " + s.obj + ": " + std::to_string(degenerate) + " triangle" + (degenerate == 1 ? "" : "s") +
                " of zero area dropped");
    }
    if (mesh.triangles.empty()) throw InputError(key + ": no triangles (" + (s.plane ? std::string("plane") : s.obj) + ")");
    if (s.transform) {
      Transform t;
      t.matrix = *s.transform;
      applyTransform(mesh, t, key + ".transform");
    }
    out.triangleSurface.insert(out.triangleSurface.end(), mesh.triangles.size(), uint32_t(i));
    out.degenerate.push_back(degenerate);
    out.mesh.append(mesh);
  }
  return out;
}

shared::Bsdf surfaceBsdf(const Surface& s) {
  shared::Bsdf b{};
  if (s.material == SurfaceMaterial::Conductor) {
    b.type = shared::BSDF_CONDUCTOR;
    b.color = s.f0;
    b.alpha = s.roughness;
  } else {
    b.type = shared::BSDF_DIFFUSE;
    b.color = s.albedo;
  }
  return b;
}

}  // namespace plume::geo
