#pragma once
#include <filesystem>
#include <vector>

#include "pipeline/console.hpp"
#include "pipeline/scene.hpp"

namespace bedforge::pipeline {

// `bedforge analyse|surface|mesh|case DIR`: one stage on a directory that a run or an earlier
// stage wrote, like an OpenFOAM utility on a case. Each reads DIR/bed.csv and DIR/scene.toml
// with `overrides` applied (InputError naming the key when they are bad), adds its stage to
// DIR/report.json and writes its files into DIR.

// Profiles and contacts of DIR/bed.csv.
void analyse_directory(const std::filesystem::path& dir, const std::vector<Override>& overrides, const Console& console);

#ifdef BEDFORGE_HAVE_CGAL
// The fluid surface of DIR/bed.csv: fluid.stl, fluid_PATCH.stl, bed.stl, fluid.vtp.
void surface_directory(const std::filesystem::path& dir, const std::vector<Override>& overrides,
                       const Console& console);
#endif

#ifdef BEDFORGE_HAVE_VOLUME_MESH
// The volume mesh of DIR/fluid.stl (refused, located, when it is not closed): fluid.msh.
void mesh_directory(const std::filesystem::path& dir, const std::vector<Override>& overrides, const Console& console);

// Piece `piece` of `pieces` of DIR/bed.csv's fluid domain as DIR/case/processor<piece>
// (piece_stage.hpp), the case written into DIR/case first, between `planes_d` (d above the floor;
// empty: meshing::slab_planes_d's; InputError naming --planes-d when they are not pieces - 1
// increasing heights inside the domain), its walls ringed with the edge of the whole bed's
// narrowest wall gap `wall_gap_m` (m; 0: found by meshing::slab_planes). Given both, the rank
// treats only its piece's window, sizing it for the memory check too (meshing::slab_domain_size;
// InputError naming mesh.pieces when the piece will not fit in this rank's share of memory).
// Every piece's report goes beside its cells, not into DIR/report.json, which the ranks would
// race for.
void piece_directory(const std::filesystem::path& dir, const std::vector<Override>& overrides, int piece, int pieces,
                     const std::vector<double>& planes_d, double wall_gap_m, const Console& console);
#endif

#ifdef BEDFORGE_HAVE_GMSH
// The OpenFOAM case of DIR/fluid.msh in DIR/case (replacing one only with `overwrite`).
void case_directory(const std::filesystem::path& dir, const std::vector<Override>& overrides, bool overwrite,
                    const Console& console);
#endif

}  // namespace bedforge::pipeline
