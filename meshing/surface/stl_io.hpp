#pragma once
#include <filesystem>
#include <ostream>
#include <string>

#include "meshing/surface/triangle_mesh.hpp"

namespace bedforge::meshing {

// Rounds every coordinate to the 12 significant digits write_stl_ascii_by_patch keeps, so that a
// surface read back from its STL is the one in memory, and both mesh the same points. It also
// keeps gmsh's Delaunay fast: at full precision a sphere's points are cospherical to rounding and
// its predicates fall back to exact arithmetic on nearly every test.
void round_to_ascii_stl(TriangleMesh& mesh);
// One coordinate so rounded (a value it leaves as it is: a height planes and rings share).
double round_to_ascii_stl(double x);

// ASCII STL with one named solid per patch (`solid inlet ... endsolid inlet`), the layout
// snappyHexMesh and surfaceFeatureExtract read as separate regions. Coordinates in metres.
void write_stl_ascii_by_patch(std::ostream& out, const TriangleMesh& mesh);

// Reads what write_stl_ascii_by_patch wrote (any ASCII STL: every `solid NAME` becomes a patch)
// and joins the vertices with identical coordinates. InputError naming `source` and the line
// on a malformed file.
TriangleMesh read_stl_ascii_by_patch(const std::string& text, const std::string& source);
// The same from a file (InputError naming it when it cannot be read).
TriangleMesh read_stl_ascii_by_patch(const std::filesystem::path& file);

// Binary STL of the triangles of one patch (all triangles when `patch` < 0); `header` goes
// into the 80-byte header (truncated).
void write_stl_binary(std::ostream& out, const TriangleMesh& mesh, int patch, const std::string& header);

}  // namespace bedforge::meshing
