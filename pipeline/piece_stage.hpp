#pragma once
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "cases/case_params.hpp"
#include "core/bed.hpp"
#include "meshing/surface/fluid_surface.hpp"
#include "meshing/volume/volume_mesh.hpp"
#include "pipeline/case_stage.hpp"
#include "pipeline/console.hpp"

namespace bedforge::pipeline {

// One piece of a decomposed case, the work of one rank: slab `piece` (from 0, bottom up) of
// `pieces` of the fluid domain of `bed` under `surface`, between `planes` (d, pieces - 1 of them,
// meshing::slab_planes_d; meshing::mesh_slab with `mesh`), written
// as case_dir/processor<piece> (cases::write_case_piece; the case's 0/ must be written) with
// processor patches to the neighbouring pieces. On gmsh's cells: the slab's, its planes made
// processor patches (meshing::make_processor_patches). On their polyhedral dual
// (`case_params.polyhedra`): whole dual cells across the planes (meshing/volume/dual_pieces.hpp),
// for which the rank writes its tetrahedra next to each shared plane to
// case_dir/piece_layers/piece<piece>_<inlet|outlet>.bin and reads its neighbours'; ranks of one
// Open MPI job (OMPI_COMM_WORLD_SIZE = pieces) wait for each other's, a piece made alone takes
// them as an earlier job left them. No process holds more than its own slab and its neighbours'
// layers. A rerun keeps what an earlier one made from the same inputs (`bed_key`, the bed file's
// stage_key, the parameters, the version and the count): on gmsh's cells its processor
// directory as it is; on polyhedra its tetrahedra (kept as case_dir/piece_layers/
// piece<piece>_tetrahedra.bin, until the run's pieces are all done), its dual made again. Then
// the piece's processor patches are compared with their copies across its planes as OpenFOAM will
// compare them (meshing::compare_processor_faces, from each piece's cases::kProcessorFacesFile): in
// a job with its neighbours' once they are written (each says so in
// case_dir/piece_layers/piece<k>_written), alone with the neighbours already there; std::runtime_error
// naming the pieces and the first face when they differ, the faces written to
// case_dir/mismatched_faces_procBoundary<k>to<n>.csv. Returns the piece's report (also written beside its cells): its cells, the fluid
// volume of its slab's tetrahedra (m^3) and their share of the bed section's void fraction as
// meshed (cases::bed_section; the pieces' shares add up to it), the slab's report, time and peak
// memory.
// InputError, before any work, when case_dir/0 is not there, prism layers are asked for or the
// treatments cannot be cut in pieces (meshing::slabs_possible, pieces_possible), or a piece on polyhedra made alone finds no neighbour's layer;
// the errors of mesh_slab otherwise, naming the piece (meshing::SlabCutError when it cannot be cut).
nlohmann::json piece_stage(const Bed& bed, const std::string& bed_key, const meshing::SurfaceParams& surface,
                           const std::vector<double>& planes, const meshing::VolumeMeshParams& mesh,
                           const cases::CaseParams& case_params, int piece, int pieces,
                           const std::filesystem::path& case_dir, const std::string& note, const Console& console);

// The inlet's and outlet's heights (m) of the fluid domain of `bed` under `surface` (its clip
// window's ends when it has one), as its pieces and the case that holds them take them.
std::pair<double, double> domain_heights(const Bed& bed, const meshing::SurfaceParams& surface);

// What mpirun's output `log` (case/log.pieces) and its exit code say of a job whose ranks did not
// all succeed: the first line a rank wrote starting "bedforge: " (its error; "" when none did),
// whether mpirun had too few slots, the rank that stopped first (-1 when mpirun did not name it,
// which it does not always do) and the signal that ended it (0 and "" when it exited on its own).
struct RanksLog {
  std::string message;
  bool too_few_slots = false;
  int failed_rank = -1;
  int signal = 0;
  std::string signal_name;
};
RanksLog read_ranks_log(const std::filesystem::path& log, int mpirun_exit_code);

// The pieces of the case a run writes (case_stage with CasePieces): `pieces` ranks started as
// `mpirun -np pieces <this program> piece run_dir` (run_dir holds bed.csv and scene.toml as run,
// the case is run_dir/case), their reports summed into the case's info. mpirun's output goes to
// case/log.pieces; when a rank fails, its message, as InputError or ConvergenceError when it was
// one (std::runtime_error otherwise), naming the piece that stopped first and its heights; a rank
// killed by signal 9 as InputError naming mesh.pieces (the kernel's out-of-memory killer, most
// likely). The ranks are given the planes (`piece --planes-d`) as piece_directory would make
// them, and the whole bed's wall gap (`--wall-gap-m`), so that each treats only its window. When
// a rank's piece cannot be cut (meshing::SlabCutError, known by its message) or fails the gate,
// the ranks run once more with the planes moved (meshing::attempt_with_planes_moved; their output
// in case/log.pieces_planes_moved): only the planes of the piece that stopped first when mpirun
// names it (every plane when not), so that the pieces whose windows reach no moved plane keep the
// tetrahedra they made; the error then names both attempts. The ranks' files (case/piece_layers)
// are removed once all have succeeded; a failed run leaves them for the next, which remakes only
// the failed pieces. The ranks compare the two sides of every plane (piece_stage): a mismatch
// stops the run with the rank's message.
// InputError naming mesh.pieces when mpirun has fewer slots than ranks (more ranks than cores
// need OMPI_MCA_rmaps_base_oversubscribe=1). `bed` must outlive the returned CasePieces.
CasePieces case_pieces(const Bed& bed, const meshing::SurfaceParams& surface, int pieces,
                       const std::filesystem::path& run_dir, const Console& console);

}  // namespace bedforge::pipeline
