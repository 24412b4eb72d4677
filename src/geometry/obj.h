// Wavefront OBJ meshes (DESIGN §9 `surfaces[].obj`): positions `v`, optional normals `vn`, faces
// `f` of 3 or more vertices in the forms i, i/t, i//n, i/t/n (negative indices count back from
// the last element defined so far), several objects (`o`, `g`). Polygons are fan-triangulated
// from their first vertex. Texture coordinates and materials are read past; other statements of
// the OBJ specification (curves, smoothing groups, ...) are ignored; anything else is an error.
// Errors are InputError naming the file and the line ("ground.obj:12: ..."): an unreadable file,
// a malformed line, an index out of range, a NaN or infinite coordinate. Triangles of zero area
// (collinear in double precision, e.g. a repeated vertex) are dropped and counted, so that the
// caller can warn.
#pragma once

#include "geometry/mesh.h"

#include <istream>
#include <string>

namespace plume::geo {

struct ObjStats {
  size_t faces = 0;       // `f` statements
  size_t triangles = 0;   // triangles kept
  size_t degenerate = 0;  // triangles of zero area, dropped
};

struct ObjMesh {
  TriangleMesh mesh;
  ObjStats stats;
};

ObjMesh loadObj(const std::string& path);
// `name` prefixes the error messages (the file's path for loadObj).
ObjMesh parseObj(std::istream& in, const std::string& name);

}  // namespace plume::geo
