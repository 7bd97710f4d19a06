#include "pipeline/piece_stage.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <numeric>
#include <optional>
#include <regex>
#include <thread>
#include <tuple>
#include <vector>

#include "cases/case_writer.hpp"
#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/report.hpp"
#include "core/version.hpp"
#include "core/stage_meter.hpp"
#include "meshing/volume/dual_mesh.hpp"
#include "meshing/volume/dual_pieces.hpp"
#include "meshing/volume/flat_ears.hpp"
#include "meshing/volume/processor_patches.hpp"
#include "meshing/volume/slab_mesh.hpp"
#include "pipeline/mesh_stage.hpp"

namespace bedforge::pipeline {

namespace {

namespace fs = std::filesystem;

// Where piece `piece` leaves its tetrahedra next to its plane `plane` ("inlet" or "outlet") for
// the piece across it (meshing/volume/dual_pieces.hpp).
fs::path layer_path(const fs::path& case_dir, int piece, const std::string& plane) {
  return case_dir / "piece_layers" / fmt::format("piece{}_{}.bin", piece, plane);
}

// Open MPI's job when this process is one of `pieces` ranks started together, "" otherwise: the
// ranks of one job wait for each other's layers, and never take an earlier job's.
std::string mpi_job(int pieces) {
  const char* size = std::getenv("OMPI_COMM_WORLD_SIZE");
  const char* job = std::getenv("OMPI_MCA_ess_base_jobid");
  return size && job && std::to_string(pieces) == size ? job : "";
}

// A layer's tag: the job that wrote it ("" outside one), then what its plane's cells are made
// from (`made_from`: the bed, the settings and the plane's height).
std::string layer_tag(const std::string& job, const std::string& made_from) { return job + " " + made_from; }
std::string made_from_of(const std::string& tag) { return tag.substr(tag.find(' ') + 1); }

// Waits until `read_tag(path)` reads `tag`, polling the file's time: a rank of the job writes
// it, and a rank that fails ends the job, so the wait ends too.
void wait_for_tag(const fs::path& path, const std::string& tag,
                  const std::function<std::string(const fs::path&)>& read_tag) {
  std::optional<fs::file_time_type> seen;
  for (;;) {
    std::error_code ec;
    const fs::file_time_type at = fs::last_write_time(path, ec);
    if (!ec && at != seen) {
      seen = at;
      if (read_tag(path) == tag) return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
}

// The layer piece `neighbour` wrote at `path`: in a job, waited for until the job's own, `tag`,
// is there; outside one, as it is (its tag checked before any work).
meshing::PlaneLayer neighbour_layer(const fs::path& path, int neighbour, const std::string& job,
                                    const std::string& tag, Progress& progress) {
  if (job.empty()) return meshing::read_plane_layer(path);
  progress.update(fmt::format("waiting for piece {}'s cells next to this one", neighbour));
  wait_for_tag(path, tag, meshing::read_plane_layer_tag);
  return meshing::read_plane_layer(path);
}

// The planes (d) that can shape piece `piece`'s surface: its own and any other its window reaches
// (rung on its walls, or near its spheres' ends), which lie within the margin of its spheres plus
// their diameters. A piece whose planes these are is the same piece when the others move.
nlohmann::json planes_reaching(const Bed& bed, const meshing::SurfaceParams& surface, const std::vector<double>& planes,
                               int piece) {
  const double reach = meshing::piece_margin_d(bed, surface) + 2.0 * largest_diameter(bed) / reference_diameter(bed);
  const int pieces = static_cast<int>(planes.size()) + 1;
  const double lo = piece > 0 ? planes[piece - 1] - reach : -std::numeric_limits<double>::infinity();
  const double hi = piece + 1 < pieces ? planes[piece] + reach : std::numeric_limits<double>::infinity();
  nlohmann::json out = nlohmann::json::object();
  for (std::size_t j = 0; j < planes.size(); ++j)
    if (planes[j] >= lo && planes[j] <= hi) out[std::to_string(j)] = planes[j];
  return out;
}

// Where piece `piece` says, by the job that wrote or kept it, that its processor directory is
// complete, for the ranks that compare their planes with it.
fs::path written_path(const fs::path& case_dir, int piece) {
  return case_dir / "piece_layers" / fmt::format("piece{}_written", piece);
}

// Piece `piece`'s processor patches against their copies across its planes, compared as OpenFOAM
// will compare them when it reads the case: a mismatch stops the run here, naming the plane and
// the faces (written beside the case), instead of in checkMesh or the solver. Every patch of the
// piece must face another piece, and the piece and each neighbour (its patches' and the pieces
// beside it) must have patches towards each other. In a job (`job`) the neighbours' directories
// are waited for, and the faces of each plane compared once, by the piece below it; outside one,
// the neighbours already written are compared, on both sides.
void check_processor_planes(const fs::path& case_dir, int piece, int pieces, const std::string& job,
                            Progress& progress) {
  const auto record = [&case_dir](int k) { return case_dir / fmt::format("processor{}", k) / cases::kProcessorFacesFile; };
  const std::vector<meshing::ProcessorFaces> mine = meshing::read_processor_faces(record(piece));
  const auto stop = [&](int n, const std::string& what, const std::string& faces) {
    throw std::runtime_error(fmt::format(
        "the case's pieces {} and {} do not match at the plane between them, which OpenFOAM would refuse or read "
        "wrong: {}{}; a defect of bedforge (please report it with the scene); the pieces are left in {} for "
        "inspection",
        std::min(piece, n) + 1, std::max(piece, n) + 1, what, faces.empty() ? "" : "; the faces: " + faces,
        case_dir.string()));
  };
  std::vector<int> neighbours;
  for (const int n : {piece - 1, piece + 1})
    if (n >= 0 && n < pieces) neighbours.push_back(n);
  for (const meshing::ProcessorFaces& p : mine) {
    if (p.neighbour < 0 || p.neighbour >= pieces || p.neighbour == piece)
      stop(p.neighbour, fmt::format("processor{} has a patch towards processor{}, not one of the {} pieces' others",
                                    piece, p.neighbour, pieces), "");
    if (std::find(neighbours.begin(), neighbours.end(), p.neighbour) == neighbours.end())
      neighbours.push_back(p.neighbour);
  }
  const auto towards = [](const std::vector<meshing::ProcessorFaces>& sides, int n) {
    return std::find_if(sides.begin(), sides.end(), [n](const meshing::ProcessorFaces& p) { return p.neighbour == n; });
  };
  for (const int n : neighbours) {
    if (!job.empty()) {
      progress.update(fmt::format("waiting for piece {} to compare the plane between them", n + 1));
      wait_for_tag(written_path(case_dir, n), job, [](const fs::path& p) { return read_file(p); });
    } else if (!fs::exists(record(n))) {
      continue;  // not written yet: compared when it is
    }
    const std::vector<meshing::ProcessorFaces> theirs = meshing::read_processor_faces(record(n));
    const auto to_n = towards(mine, n);
    const auto back = towards(theirs, piece);
    if (to_n == mine.end()) stop(n, fmt::format("processor{} has no patch procBoundary{}to{}", piece, piece, n), "");
    if (back == theirs.end()) stop(n, fmt::format("processor{} has no patch procBoundary{}to{}", n, n, piece), "");
    if (!job.empty() && n < piece) continue;  // compared by the piece below
    const meshing::ProcessorFaces& lower = n > piece ? *to_n : *back;
    const meshing::ProcessorFaces& upper = n > piece ? *back : *to_n;
    const meshing::ProcessorMismatch mismatch = meshing::compare_processor_faces(lower, upper);
    if (mismatch.what.empty()) continue;
    const fs::path faces =
        case_dir / fmt::format("mismatched_faces_procBoundary{}to{}.csv", lower.processor, upper.processor);
    meshing::write_processor_mismatch(faces, lower, upper, mismatch);
    stop(n, mismatch.what, faces.string());
  }
}

// piece_stage's piece, made or kept, before its planes are compared; `job` as mpi_job gives it.
nlohmann::json made_piece(const Bed& bed, const std::string& bed_key, const meshing::SurfaceParams& surface,
                          const std::vector<double>& planes, const meshing::VolumeMeshParams& mesh,
                          const cases::CaseParams& case_params, int piece, int pieces, const fs::path& case_dir,
                          const std::string& note, const std::string& job, Progress& progress) {
  const StageMeter meter;
  if (static_cast<int>(planes.size()) + 1 != pieces)
    throw std::invalid_argument(fmt::format("piece stage: {} planes for {} pieces", planes.size(), pieces));
  if (!std::filesystem::is_directory(case_dir / "0"))
    throw InputError(fmt::format("{}: no case to write a piece into (no 0/ fields); write the case first, e.g. "
                                 "`bedforge run` with case.run = false",
                                 case_dir.string()));
  if (!meshing::slabs_possible(mesh) || !meshing::pieces_possible(surface, *bed.container))
    throw InputError(fmt::format("contacts.treatment = \"{}\", contacts.wall_treatment = \"{}\", mesh.layers.count = "
                                 "{}: a piece's planes would cut prism layers open, or a box's sides unlike its "
                                 "neighbour's; allowed for pieces: mesh.layers.count = 0, and in a box "
                                 "contacts.treatment and contacts.wall_treatment \"shrink\" or \"none\"",
                                 meshing::treatment_name(surface.treatment),
                                 meshing::treatment_name(surface.wall_treatment), mesh.layers.count));
  // What every piece's cells are made from, and the cells at plane j (between pieces j and j + 1),
  // which both pieces' layers there must share.
  const nlohmann::json settings = {{"version", kVersion}, {"bed", bed_key}, {"surface", meshing::to_json(surface)},
                                   {"mesh", meshing::to_json(mesh)}, {"pieces", pieces}};
  const auto plane_made_from = [&](int j) { return stage_key({{"settings", settings}, {"plane_d", planes[j]}}); };
  // The tag of a layer at plane j that this job writes and its neighbours read back.
  const auto tag_at = [&](int j) { return layer_tag(job, plane_made_from(j)); };
  // A piece on polyhedra made on its own takes its neighbours' layers as an earlier job left them,
  // made at the same planes of the same bed and settings.
  if (case_params.polyhedra && job.empty())
    for (const auto& [neighbour, plane] : {std::pair{piece - 1, "outlet"}, std::pair{piece + 1, "inlet"}}) {
      if (neighbour < 0 || neighbour >= pieces) continue;
      const fs::path path = layer_path(case_dir, neighbour, plane);
      const std::string allowed = fmt::format(
          "allowed: the pieces of a case on polyhedra made together (`mpirun -np {} bedforge piece DIR`, or `bedforge "
          "run` with mesh.pieces = {}), or case.cells = \"tetrahedra\"", pieces, pieces);
      if (!fs::exists(path))
        throw InputError(fmt::format("{}: piece {}'s cells next to piece {} are not there; {}", path.string(),
                                     neighbour, piece, allowed));
      const int j = std::min(piece, neighbour);
      if (made_from_of(meshing::read_plane_layer_tag(path)) != plane_made_from(j))
        throw InputError(fmt::format("{}: piece {}'s cells next to piece {} were made for another bed, other settings "
                                     "or another plane than {:.17g} d; {}",
                                     path.string(), neighbour, piece, planes[j], allowed));
    }
  const double d = reference_diameter(bed);
  // What the piece's tetrahedra and its processor directory are made from: a rerun keeps what
  // an earlier run made from the same, so only the pieces that failed, or whose planes moved, are
  // meshed again.
  const std::string cells_key = stage_key(
      {{"settings", settings}, {"planes_d", planes_reaching(bed, surface, planes, piece)}, {"piece", piece}});
  const std::string piece_key = stage_key({{"cells", cells_key}, {"case", cases::to_json(case_params)}});
  const fs::path piece_dir = case_dir / fmt::format("processor{}", piece);
  if (!case_params.polyhedra && fs::exists(piece_dir / "bedforge_piece.json") &&
      fs::exists(piece_dir / cases::kProcessorFacesFile)) {
    nlohmann::json earlier = nlohmann::json::parse(read_file(piece_dir / "bedforge_piece.json"));
    if (earlier.value("key", "") == piece_key) {
      earlier["reused"] = true;
      return earlier;
    }
  }
  // On polyhedra the dual is made again (its neighbours' may be new), from the tetrahedra kept.
  const fs::path kept = layer_path(case_dir, piece, "tetrahedra");
  meshing::VolumeMesh slab;
  if (case_params.polyhedra && fs::exists(kept) && meshing::read_plane_layer_tag(kept) == cells_key) {
    progress.update(fmt::format("piece {} of {}: an earlier run's cells", piece + 1, pieces));
    slab.mesh = meshing::slab_of(meshing::read_plane_layer(kept)), slab.report = {{"reused", true}};
  }
  if (slab.mesh.cells == 0) {
    progress.update(fmt::format("piece {} of {}: surface and cells", piece + 1, pieces));
    try {
      slab = meshing::mesh_slab(bed, surface, planes, piece, d, mesh,
                                case_dir / fmt::format("bad_cells_piece{}.vtk", piece), true);
    } catch (const meshing::SlabCutError& e) {
      throw meshing::SlabCutError(fmt::format("{}; allowed: other planes (piece --planes-d), or another mesh.pieces",
                                              e.what()));
    }
    if (case_params.polyhedra) {
      meshing::PlaneLayer all = meshing::whole_slab(slab.mesh);
      all.tag = cells_key;
      meshing::write_plane_layer(kept, all);
    }
  }
  // The bed section of the whole domain, and the piece's share of its void fraction as meshed.
  const auto [inlet_z, outlet_z] = domain_heights(bed, surface);
  const cases::CaseGeometry g = cases::case_geometry({Eigen::Vector3d(0, 0, inlet_z), Eigen::Vector3d(0, 0, outlet_z)}, bed);
  const meshing::CellGeometry cells = meshing::cell_geometry(slab.mesh);
  const cases::BedSection section = cases::bed_section(&cells, g, case_params.section_exclude_d);
  nlohmann::json report = {{"piece", piece},
                           {"pieces", pieces},
                           {"key", piece_key},
                           {"slab", slab.report},
                           {"fluid_volume_m3", std::accumulate(cells.volumes.begin(), cells.volumes.end(), 0.0)},
                           {"section_void_fraction_share", section.void_fraction.value()},
                           {"section_z_m", {section.z_low, section.z_high}}};
  if (case_params.polyhedra) {
    // Whole dual cells across the planes: each neighbour's tetrahedra next to the plane shared
    // with it, written by its rank as this rank writes its own (dual_pieces.hpp).
    for (const auto& [plane, shared] : {std::pair{"inlet", piece > 0}, std::pair{"outlet", piece + 1 < pieces}})
      if (shared) {
        meshing::PlaneLayer layer = meshing::plane_layer(slab.mesh, plane);
        layer.tag = tag_at(plane == std::string("inlet") ? piece - 1 : piece);
        meshing::write_plane_layer(layer_path(case_dir, piece, plane), layer);
      }
    std::optional<meshing::PlaneLayer> below, above;
    if (piece > 0)
      below = neighbour_layer(layer_path(case_dir, piece - 1, "outlet"), piece - 1, job, tag_at(piece - 1), progress);
    if (piece + 1 < pieces)
      above = neighbour_layer(layer_path(case_dir, piece + 1, "inlet"), piece + 1, job, tag_at(piece), progress);
    progress.update(fmt::format("piece {} of {}: polyhedra", piece + 1, pieces));
    meshing::SlabWithLayers whole =
        meshing::slab_with_layers(slab.mesh, below ? &*below : nullptr, above ? &*above : nullptr);
    slab = meshing::VolumeMesh();
    below.reset(), above.reset();
    release_free_memory();  // the tetrahedra
    // Flat ears cut as the one-piece route cuts them (a plane between pieces is internal to
    // `whole` on both sides of it, so both decide alike); counted by each piece with a point of it.
    const std::vector<int> ears = meshing::flat_ears(whole.mesh);
    std::vector<char> counted(ears.size(), 0);
    for (const auto& patch : whole.mesh.patches)
      for (int f = patch.start; f < patch.start + patch.size; ++f)
        if (const auto e = std::lower_bound(ears.begin(), ears.end(), whole.mesh.owner[f]);
            e != ears.end() && *e == whole.mesh.owner[f])
          for (int v : whole.mesh.faces[f]) counted[e - ears.begin()] |= whole.side[v] == 0;
    meshing::cut_ears(whole.mesh, ears);
    std::vector<int> cell_points;
    meshing::PolyhedralMesh dual = meshing::dual_mesh(whole.mesh, meshing::tetrahedron_centroids(whole.mesh),
                                                      cases::kDualFeatureAngleDeg, &cell_points);
    const std::vector<int> side = std::move(whole.side);
    whole = meshing::SlabWithLayers();
    release_free_memory();
    // The piece's own polyhedra, checked against checkMesh's limits with its neighbours' cells
    // around them, whose centres the faces across the planes see (as `checkMesh -parallel` does).
    std::vector<bool> own(dual.cells);
    for (int c = 0; c < dual.cells; ++c) own[c] = side[cell_points[c]] == 0;
    meshing::JudgedQuality quality =
        meshing::check_polyhedra(dual, std::move(own), &cell_points, bed, d,
                                fmt::format("piece {} of {}'s polyhedra", piece + 1, pieces),
                                case_dir / fmt::format("bad_polyhedra_piece{}.vtk", piece));
    quality.ears_cut = std::count(counted.begin(), counted.end(), 1);
    report["polyhedra_quality"] = quality.to_json(d);
    dual = meshing::dual_piece(dual, cell_points, side, piece, pieces);
    report["cells"] = dual.cells;
    meter.record(report);
    cases::write_case_piece(case_dir, piece, dual, case_params.binary, note, report);
  } else {
    meshing::make_processor_patches(slab.mesh, piece, pieces);
    report["cells"] = slab.mesh.cells;
    meter.record(report);
    cases::write_case_piece(case_dir, piece, slab.mesh, case_params.binary, note, report);
  }
  progress.update(fmt::format("piece {} of {}: {} cells written", piece + 1, pieces, report["cells"].get<long>()));
  return report;
}

}  // namespace

nlohmann::json piece_stage(const Bed& bed, const std::string& bed_key, const meshing::SurfaceParams& surface,
                           const std::vector<double>& planes, const meshing::VolumeMeshParams& mesh,
                           const cases::CaseParams& case_params, int piece, int pieces,
                           const std::filesystem::path& case_dir, const std::string& note, const Console& console) {
  const std::string job = mpi_job(pieces);
  Progress progress("piece", console.progress);
  const nlohmann::json report =
      made_piece(bed, bed_key, surface, planes, mesh, case_params, piece, pieces, case_dir, note, job, progress);
  // The job's ranks compare their planes once each has written (or kept) its directory.
  if (!job.empty()) {
    fs::create_directories(written_path(case_dir, piece).parent_path());
    write_file_atomically(written_path(case_dir, piece), job);
  }
  check_processor_planes(case_dir, piece, pieces, job, progress);
  progress.finish();
  return report;
}

std::pair<double, double> domain_heights(const Bed& bed, const meshing::SurfaceParams& surface) {
  const meshing::SurfaceParams whole = meshing::slab_surface(bed, surface, {}, 0);
  const double d = reference_diameter(bed);
  return {whole.clip_bottom_d * d, whole.clip_top_d * d};
}

RanksLog read_ranks_log(const std::filesystem::path& log, int mpirun_exit_code) {
  // Open MPI 4.1's words (Debian 12) for a rank killed, a rank's non-zero exit and too few slots.
  static const std::regex killed(R"(process rank (\d+) with PID \d+ on node \S+ exited on signal (\d+) \(([^)]*)\))"),
      first(R"(Process name: \[\[\d+,\d+\],(\d+)\])");
  RanksLog out;
  std::ifstream in(log);
  std::string line;
  std::smatch m;
  while (std::getline(in, line)) {
    if (line.rfind("bedforge: ", 0) == 0 && out.message.empty()) out.message = line;
    out.too_few_slots = out.too_few_slots || line.find("not enough slots available") != std::string::npos;
    if (out.signal == 0 && std::regex_search(line, m, killed)) {
      out.failed_rank = std::stoi(m[1]), out.signal = std::stoi(m[2]), out.signal_name = m[3];
    } else if (out.failed_rank < 0 && std::regex_search(line, m, first)) {
      out.failed_rank = std::stoi(m[1]);
    }
  }
  // mpirun does not always name the rank (it races with its own abort), but it exits with 128 +
  // the signal that ended the first rank to stop.
  if (out.signal == 0 && mpirun_exit_code > 128) {
    out.signal = mpirun_exit_code - 128;
    out.signal_name = strsignal(out.signal);
  }
  return out;
}

CasePieces case_pieces(const Bed& bed, const meshing::SurfaceParams& surface, int pieces,
                       const std::filesystem::path& run_dir, const Console& console) {
  CasePieces out;
  out.count = pieces;
  std::tie(out.inlet_z, out.outlet_z) = domain_heights(bed, surface);
  // The ranks are given `planes` (d) and the whole bed's wall gap (`wall_gap_m`, m), each try its
  // log (`log_name`).
  // The piece whose rank stopped first in the last try (-1: none named): the planes moved are its.
  auto failed_piece = std::make_shared<int>(-1);
  const auto run_ranks = [&bed, surface, pieces, run_dir, &console, failed_piece](const fs::path& case_dir,
                                                                                  const std::vector<double>& planes,
                                                                                  double wall_gap_m,
                                                                                  const std::string& log_name) {
    const fs::path self = fs::read_symlink("/proc/self/exe"), log = case_dir / log_name;
    Progress progress("pieces", console.progress);
    progress.update(fmt::format("{} ranks, each meshing its piece (mpirun)", pieces));
    // Open MPI refuses root unless told (containers, CI), as in Allrun.
    const std::string cmd = fmt::format(
        "[ \"$(id -u)\" = 0 ] && export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; "
        "mpirun -np {} '{}' --quiet --no-progress piece '{}' --planes-d {}{} > '{}' 2>&1", pieces, self.string(),
        run_dir.string(), fmt::join(planes, " "),
        // Infinite (no curved wall, or no sphere near one) is given too, or each rank would survey
        // the bed for it.
        wall_gap_m > 0.0 ? fmt::format(" --wall-gap-m {:.17g}", wall_gap_m) : "",
        log.string());
    const int status = std::system(cmd.c_str());
    progress.finish();
    if (status == 0) return;
    const RanksLog said = read_ranks_log(log, WIFEXITED(status) ? WEXITSTATUS(status) : 0);
    if (said.too_few_slots)
      throw InputError(fmt::format(
          "mesh.pieces = {}: mpirun has fewer slots than {} ranks here (see {}); allowed: mesh.pieces at most the "
          "slots (this machine's cores, or the batch job's tasks), or more ranks than cores with "
          "OMPI_MCA_rmaps_base_oversubscribe=1 in the environment (each rank still holds only its piece; the "
          "ranks share the cores)",
          pieces, pieces, log.string()));
    // Which piece stopped first, with its heights: a rank's own message may not say.
    std::string which = "a rank";
    *failed_piece = said.failed_rank >= 0 && said.failed_rank < pieces ? said.failed_rank : -1;
    if (said.failed_rank >= 0 && said.failed_rank < pieces) {
      const meshing::SurfaceParams slab = meshing::slab_surface(bed, surface, planes, said.failed_rank);
      which = fmt::format("piece {} of {} ({:.2f}-{:.2f} d above the floor, rank {})", said.failed_rank + 1, pieces,
                          slab.clip_bottom_d, slab.clip_top_d, said.failed_rank);
    }
    // Killed from outside, with no word of its own: on a machine short of memory, the kernel's
    // out-of-memory killer, which the ranks' check (refuse_piece_beyond_memory) did not foresee.
    if (said.signal == 9)
      throw InputError(fmt::format(
          "mesh.pieces = {}: {} was killed by signal 9 ({}), most likely by the kernel for want of memory (each "
          "rank checks its piece against its share of this machine's memory before it starts, by {}); allowed: "
          "{}{}; see {}",
          pieces, which, said.signal_name, piece_memory_basis(surface.cells_per_gap > 0.0),
          pieces_memory_remedies("more pieces"),
          surface.cells_per_gap > 0.0 ? "; " + gaps_remedy(surface) : std::string(), log.string()));
    if (said.signal > 0)
      throw std::runtime_error(fmt::format("the case's pieces: {} stopped on signal {} ({}); see {}", which,
                                           said.signal, said.signal_name, log.string()));
    // Stopped as the rank stopped: bad input, a gate not passed, or a defect.
    const std::string what = fmt::format("the case's pieces: mpirun -np {} {} piece failed ({}{}); see {}", pieces,
                                         self.filename().string(), which == "a rank" ? "" : which + ": ",
                                         said.message.empty() ? "no rank said why" : said.message, log.string());
    if (said.message.rfind("bedforge: error: ", 0) == 0) {
      if (said.message.find(meshing::kSlabCutPhrase) != std::string::npos) throw meshing::SlabCutError(what);
      throw InputError(what);
    }
    if (said.message.rfind("bedforge: did not converge: ", 0) == 0) throw ConvergenceError(what);
    throw std::runtime_error(what);
  };
  out.write = [&bed, surface, pieces, run_ranks, failed_piece, &console](cases::CaseInfo& info) {
    // The planes and the whole bed's wall gap from one survey of it, here, so that each rank
    // treats only its piece's window (piece_directory).
    const meshing::SlabPlanes given = meshing::slab_planes(bed, surface, pieces);
    release_free_memory();  // the survey's, kept by the allocator, from the ranks started on this machine
    bool moved = false;
    meshing::attempt_with_planes_moved(
        bed, surface, given.planes_d, "mesh.pieces",
        [&](const std::vector<double>& at) {
          run_ranks(info.directory, at, given.wall_gap_m, moved ? "log.pieces_planes_moved" : "log.pieces");
        },
        [&console, &moved](const meshing::PlanesMoved& m) {
          moved = true;
          console.line(fmt::format("pieces: {}; meshing again with the planes moved from {:.3f} to {:.3f} d "
                                   "(a piece whose planes stayed keeps the cells it made)",
                                   m.because, fmt::join(m.from_d, ", "), fmt::join(m.to_d, ", ")));
        },
        // A rank that stopped first named: only its planes move (a rank stopped on its neighbour's
        // failure says so later, if at all).
        [failed_piece] { return *failed_piece >= 0 ? std::vector<int>{*failed_piece} : std::vector<int>{}; });
    fs::remove_all(layer_path(info.directory, 0, "outlet").parent_path());  // served its purpose
    long cells = 0;
    double fluid = 0.0, void_fraction = 0.0;
    for (int k = 0; k < pieces; ++k) {
      const nlohmann::json r = nlohmann::json::parse(read_file(info.directory / fmt::format("processor{}/bedforge_piece.json", k)));
      cells += r["cells"].get<long>();
      fluid += r["fluid_volume_m3"].get<double>();
      void_fraction += r["section_void_fraction_share"].get<double>();
      // The pieces' polyhedra against checkMesh's limits, as one mesh's (meshing::check_polyhedra).
      if (const auto q = r.find("polyhedra_quality"); q != r.end()) {
        const auto piece = meshing::JudgedQuality::from_json(*q, info.d_ref_m);
        if (info.polyhedra_quality) info.polyhedra_quality->add(piece);
        else info.polyhedra_quality = piece;
      }
    }
    info.cells = cells;
    info.fluid_volume_m3 = fluid;
    info.section.void_fraction = void_fraction;
  };
  return out;
}

}  // namespace bedforge::pipeline
