#pragma once
#include <ostream>
#include <string>

#include "meshing/surface/triangle_mesh.hpp"

namespace bedforge::meshing {

// VTK XML PolyData (.vtp) of a labelled triangle mesh, for ParaView: the points (m), the
// triangles, and a cell array `patch` (the index into mesh.patches; the names are listed in
// the file's leading comment, and in an integer FieldData array per name, so a Threshold on
// `patch` picks one). Raw appended binary, little-endian, 64-bit headers. `comment` (e.g. the
// version and scene) goes into the leading XML comment.
void write_vtp(std::ostream& out, const TriangleMesh& mesh, const std::string& comment);

}  // namespace bedforge::meshing
