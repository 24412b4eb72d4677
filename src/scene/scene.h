// The scene file (DESIGN §9): parsing and validation. Every error is an InputError of the form
// "<file>: <key path>: <what is wrong>", e.g. "scene.json: media[0].albedo: expected 3 numbers
// in [0,1]". Unknown keys are errors. Relative paths resolve against the scene file's folder.
#pragma once

#include "scene/settings.h"

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <nlohmann/json_fwd.hpp>

#include <optional>
#include <string>
#include <vector>

namespace plume {

struct CameraPose {
  glm::vec3 position{0, 1, 4};
  glm::vec3 lookAt{0, 0, 0};
  glm::vec3 up{0, 1, 0};
  float fovY = 40.0f;  // vertical, degrees
};

struct CameraKey {
  int frame = 1;
  CameraPose pose;  // fields missing in the file inherit from the previous key (or the base)
};

struct Camera {
  CameraPose base;     // acts as a key at `baseFrame`
  int baseFrame = 1;   // the first frame of the scene file's render.frames (not CLI overrides)
  int width = 320;
  int height = 180;
  std::vector<CameraKey> keys;  // sorted by frame

  // Pose at `frame`, linear between keys and held constant outside them.
  CameraPose poseAt(double frame) const;
  bool moves() const { return !keys.empty(); }
};

// A medium's emission (DESIGN §2 "Emission"): the medium emits sigma_a(x) * Le(x) radiance per
// unit length, sigma_a = sigma_t * (1 - albedo), with e(x) the emission grid trilinearly
// interpolated like the density and
//   colour:    Le(x) = scale * color * e(x)
//   blackbody: Le(x) = scale * B(T(x)), T(x) = temperature_scale * (e(x) - temperature_offset)
//              kelvin, B the normalised blackbody of core/blackbody.h (0 for T <= 100 K).
struct Emission {
  std::string grid;                // grid name in the medium's VDB (same file, same transform)
  float scale = 1.0f;
  glm::vec3 color{1.0f};           // colour form
  bool blackbody = false;
  float temperatureScale = 1.0f;   // blackbody form: kelvin per grid unit
  float temperatureOffset = 0.0f;  // blackbody form: grid value of 0 K
};

struct Medium {
  std::string vdb;                  // resolved path; may hold a {frame:04} pattern
  std::string densityGrid = "density";
  float densityScale = 1.0f;        // sigma_t = densityScale * d(x) per world unit
  glm::vec3 albedo{1.0f};
  float g = 0.0f;                   // Henyey–Greenstein, g > 0 forward
  std::optional<Emission> emission;

  bool animated() const;            // the path has a frame pattern
  std::string vdbPath(int frame) const;
};

enum class LightType { Sun, Point, Environment };

struct Light {
  LightType type = LightType::Sun;
  // sun
  glm::vec3 toLight{0, 1, 0};       // normalised on load
  glm::vec3 irradiance{0};          // W/m² perpendicular to the sun direction
  float angularRadiusDeg = 0.0f;    // 0: a delta direction
  // point
  glm::vec3 position{0};
  glm::vec3 intensity{0};           // W/sr
  // environment
  glm::vec3 radiance{0};            // constant radiance (multiplied by `scale`)
  std::string map;                  // or a lat-long EXR (resolved path), never both (DESIGN §2)
  glm::vec3 up{0, 1, 0};            // the map's +Y in world space (normalised on load)
  float rotateYDeg = 0.0f;
  float scale = 1.0f;
};

// A surface (DESIGN §2 "Surfaces", §9 `surfaces[]`): a triangle mesh from an OBJ file or the
// built-in plane, an optional affine transform, a material and an optional emission.
enum class SurfaceMaterial { Diffuse, Conductor };

// `plane`: a rectangle of size.x by size.y centred on `center`, facing `normal` (geometry/mesh.h
// makePlane: for the ground, normal +Y, size.x runs along X and size.y along Z).
struct SurfacePlane {
  glm::vec3 center{0.0f};
  glm::vec3 normal{0, 1, 0};
  glm::vec2 size{1.0f};
};

struct Surface {
  std::string obj;                     // resolved path; empty for a plane
  std::optional<SurfacePlane> plane;
  // `transform`: {"translate", "rotate_deg" (XYZ Euler: about X, then Y, then Z), "scale" (a number
  // or 3)}, x' = T R S x, or {"matrix": 16 numbers, row-major, last row 0 0 0 1}. Column-major
  // here (GLM); affine and invertible (checked on load).
  std::optional<glm::mat4> transform;
  SurfaceMaterial material = SurfaceMaterial::Diffuse;
  glm::vec3 albedo{0.5f};              // diffuse (Lambert); 0 by default for an emitter
  float roughness = 0.0f;              // conductor: GGX alpha in [0, 1] (Mitsuba's convention)
  glm::vec3 f0{1.0f};                  // conductor: reflectance at normal incidence (Schlick)
  glm::vec3 emission{0.0f};            // radiance leaving the front side (an area light)

  bool emits() const { return emission != glm::vec3(0.0f); }
};

struct Scene {
  std::string path;  // the scene file, as given
  std::string dir;   // its folder
  Camera camera;
  std::vector<Medium> media;
  std::vector<Light> lights;
  std::vector<Surface> surfaces;
  RenderSettings render;

  bool hasEnvironment() const;
  // The scene's medium: parseScene accepts exactly one (several are not supported yet).
  const Medium& medium() const { return media.at(0); }
  Medium& medium() { return media.at(0); }
};


// Reads and validates a scene file. Throws InputError.
Scene loadScene(const std::string& path);
// Validates an already parsed document; `path` is used in messages, `dir` to resolve files.
Scene parseScene(const nlohmann::json& doc, const std::string& path, const std::string& dir);

// "{frame:04}" (any width) replaced by the frame number; other text unchanged.
std::string expandFramePattern(const std::string& pattern, int frame);
bool hasFramePattern(const std::string& pattern);

}  // namespace plume
