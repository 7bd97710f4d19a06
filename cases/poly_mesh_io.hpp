#pragma once
#include <filesystem>
#include <string>

#include "meshing/volume/poly_mesh.hpp"

namespace bedforge::cases {

// Writes `mesh` as OpenFOAM's constant/polyMesh (points, faces, owner, neighbour, boundary) into
// `dir`, in binary (label 32 bit, scalar 64 bit, little-endian: what Debian's OpenFOAM reads) or
// ASCII. `note` goes into every header (scene, seed, version). Files are written in place: the
// caller writes the whole case under a temporary name.
void write_poly_mesh(const std::filesystem::path& dir, const meshing::PolyMesh& mesh, bool binary,
                     const std::string& note);
void write_poly_mesh(const std::filesystem::path& dir, const meshing::PolyhedralMesh& mesh, bool binary,
                     const std::string& note);

// OpenFOAM's file header ("FoamFile" dictionary) for an object in `location`.
std::string foam_header(const std::string& cls, const std::string& location, const std::string& object,
                        const std::string& note, bool binary = false);

}  // namespace bedforge::cases
