#pragma once
#include <ostream>
#include <string>

#include "meshing/triangle_mesh.hpp"

namespace bedforge::meshing {

// ASCII STL with one named solid per patch (`solid inlet ... endsolid inlet`), the layout
// snappyHexMesh and surfaceFeatureExtract read as separate regions. Coordinates in metres.
void write_stl_ascii_by_patch(std::ostream& out, const TriangleMesh& mesh);

// Reads what write_stl_ascii_by_patch wrote (any ASCII STL: every `solid NAME` becomes a patch)
// and joins the vertices with identical coordinates. InputError naming `source` and the line
// on a malformed file.
TriangleMesh read_stl_ascii_by_patch(const std::string& text, const std::string& source);

// Binary STL of the triangles of one patch (all triangles when `patch` < 0); `header` goes
// into the 80-byte header (truncated).
void write_stl_binary(std::ostream& out, const TriangleMesh& mesh, int patch, const std::string& header);

}  // namespace bedforge::meshing
