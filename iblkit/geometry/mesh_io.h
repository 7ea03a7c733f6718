// Meshes from files (OBJ, PLY, glTF, FBX … through assimp) and to OBJ.
#pragma once
#include <string>

#include "iblkit/geometry/mesh.h"

namespace ibl::geometry {

// Every mesh of the file's scene graph, with node transforms applied, triangulated, joined into one
// mesh (first UV channel kept when every part has one). Throws ibl::Error naming the file.
TriMesh read_mesh(const std::string& path);

// Writes positions, UVs (when present) and triangles as Wavefront OBJ.
void write_obj(const std::string& path, const TriMesh& mesh, const std::string& comment = {});

}  // namespace ibl::geometry
