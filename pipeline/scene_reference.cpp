#include "pipeline/scene_reference.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <stdexcept>
#include <tuple>
#include <vector>

#include "pipeline/scene.hpp"

namespace bedforge::pipeline {

namespace {

// Headings of docs/defaults.md (a test checks each is there).
const char* const kWhyAnswer = "The answer: a solved case is studied (`[case.convergence] levels = 3`, `ratio = 1.3`)";
const char* const kWhyContacts = "Contacts: `treatment = \"bridge\"` (a default changes the bed's solid by at most 0.5 %)";
const char* const kWhyPacker = "Packer: `mode = \"accelerated\"`, `overlap_tolerance_d = 1e-4`";
const char* const kWhySurface = "Surface: `edge_length_d = 0.15`, `contact_edge_length_d = 0.05`, `cells_per_gap = 4`";
const char* const kWhyMeshSizes = "Mesh: surface-driven sizes, `max_size_d = 0.25`, one optimiser pass";
const char* const kWhySlabs = "Mesh: `slabs = 0`, one slab per million surface triangles (shrink and none)";
const char* const kWhyLayers = "Mesh: prism layers off (`[mesh.layers] count = 0`); when on, 0.02 d, growth 1.2, "
                               "`gap_fraction = 0.2`";
const char* const kWhyResiduals = "Flow solve: `residual_p = residual_u = 1e-4`, 1e-6 on a periodic section";
const char* const kWhySettled = "Flow solve: `iteration_tolerance = 1e-3`, run on until dp/L has settled";
const char* const kWhyCells = "Case: `cells = \"polyhedra\"` (gmsh's tetrahedra turned into their dual), least-squares "
                              "gradients";

// Key suffixes that name a unit, longest first so "_d3" wins over "_d".
const std::vector<std::pair<std::string, std::string>> kSuffixUnits = {
    {"_kg_m3", "kg/m³"}, {"_pa_s", "Pa s"}, {"_deg", "degrees"}, {"_d3", "d³"}, {"_d", "d"}, {"_m", "m"}};

}  // namespace

const std::map<std::string, KeyMeaning>& scene_key_meanings() {
  // d is the particle diameter (the smallest, for a mixture); lengths in d scale with the bed.
  static const std::map<std::string, KeyMeaning> meanings = {
      // [container]
      {"container.type", {"the container's shape"}},
      {"container.diameter_d", {"cylinder or annulus outer diameter; this or `diameter_m` is required"}},
      {"container.diameter_m", {"the same in metres"}},
      {"container.inner_diameter_d", {"annulus inner diameter; this or `inner_diameter_m` is required for an annulus"}},
      {"container.inner_diameter_m", {"the same in metres"}},
      {"container.size_x_d", {"box side along x; this or `size_x_m` is required for a box"}},
      {"container.size_x_m", {"the same in metres"}},
      {"container.size_y_d", {"box side along y; this or `size_y_m` is required for a box"}},
      {"container.size_y_m", {"the same in metres"}},
      {"container.periodic_x", {"the box's two sides normal to x are periodic instead of walls; meshed (a surface, "
                                "mesh or case) only with periodic_y and period_z too, a box periodic on every side: "
                                "its sides three cyclic pairs, its spheres cut where they cross them and apart "
                                "(contacts.treatment \"none\" or \"shrink\"), compared at Re_p <= 0.01 with van der "
                                "Hoef et al.'s Stokes drag of random arrays (or Zick & Homsy's, a simple cubic "
                                "lattice); on polyhedra"}},
      {"container.periodic_y", {"the box's two sides normal to y are periodic instead of walls"}},
      {"container.period_z_d",
       {"axial period: the bed repeats along z every period, with neither floor nor top (a periodic section of a long "
        "bed; `particles.count` in one period sets its void fraction); at least 3 largest diameters; packed by the "
        "accelerated soft-sphere packer, which compresses a longer period down to this one without gravity and "
        "taps them where they jam first, or the Monte Carlo packer, which compresses it the same way between blocks of "
        "cycles without gravity (neither shakes nor settles); each stops with an error naming the void fraction it "
        "jammed at; meshed as a "
        "cyclic case, its spheres cut by the periodic planes (bridges and caps the planes cross are opened, their "
        "spheres shrunk by `contacts.shrink_factor`, or cut through: `contacts.at_periodic_planes`; enlarge only cut "
        "through)"}},
      {"container.period_z_m", {"the same in metres"}},
      // [particles]
      {"particles.count",
       {"number of spheres; 0 is the empty container, whose case is compared with the exact laminar flow through it "
        "(Hagen-Poiseuille in a tube; `scenes/examples/empty_tube_verification.toml`) instead of a correlation: the "
        "verification of the mesh-and-flow route"}},
      {"particles.distribution", {"how the diameters are distributed"}},
      {"particles.diameter_m", {"monodisperse: the diameter"}},
      {"particles.diameters_m", {"discrete: the mixture's diameters"}},
      {"particles.number_fractions", {"discrete: each diameter's share of the number; they sum to 1", "1"}},
      {"particles.volume_fractions", {"discrete: each diameter's share of the volume, instead; they sum to 1", "1"}},
      {"particles.mean_m", {"normal or lognormal: the mean diameter"}},
      {"particles.std_m", {"normal or lognormal: the diameters' standard deviation"}},
      {"particles.min_m", {"normal or lognormal: smallest diameter drawn"}},
      {"particles.max_m", {"normal or lognormal: largest diameter drawn"}},
      // [packing]
      {"packing.algorithm",
       {"soft-sphere (Salvat et al.), Monte Carlo (Abreu et al.) or a bed made elsewhere (import)"}},
      {"packing.seed", {"random seed: the same scene and seed give the same bed"}},
      {"packing.file", {"import: the bed file, relative to the scene file"}},
      {"packing.format",
       {"import: rows x y z d; a LAMMPS/LIGGGHTS text dump (last snapshot, columns x y z and radius or diameter); "
        "Yade's export.text (x y z r)"}},
      {"packing.units", {"import: the file's length unit"}},
      {"packing.origin_m", {"import: the file's point on the container axis at the floor, moved to bedforge's origin"}},
      // [packing.soft_sphere]
      {"packing.soft_sphere.mode",
       {"`faithful` follows the paper's schedule step by step; `accelerated` reaches the same packing in fewer "
        "iterations",
        "", kWhyPacker}},
      {"packing.soft_sphere.initial_void_fraction", {"eps_0 of the generation stage, Eq. (6)", "1"}},
      {"packing.soft_sphere.stiffness_step", {"C_k of Eq. (4)", "1"}},
      {"packing.soft_sphere.gravity_step_increment", {"Delta C_g of Eq. (7)", "1"}},
      {"packing.soft_sphere.overlap_band_lower_d", {"lower end of the overlap band of Eq. (7)"}},
      {"packing.soft_sphere.overlap_band_upper_d", {"upper end of the overlap band of Eq. (7)"}},
      {"packing.soft_sphere.overlap_tolerance_d", {"largest overlap left between spheres at the end", "", kWhyPacker}},
      {"packing.soft_sphere.mass_centre_interval", {"the stopping test: iterations between samples of the bed's height"}},
      {"packing.soft_sphere.mass_centre_samples", {"the stopping test: samples compared"}},
      {"packing.soft_sphere.mass_centre_tolerance", {"the stopping test: largest change of the sampled height", "d"}},
      {"packing.soft_sphere.force_tolerance", {"accelerated: rms net force over weight that ends a stage", "1"}},
      {"packing.soft_sphere.final_momentum_bound",
       {"accelerated: cap on the momentum parameter t in the final stage, 0 for none", "1"}},
      {"packing.soft_sphere.max_iterations", {"iteration cap over all stages: the run stops with exit status 3 past it"}},
      {"packing.soft_sphere.max_recoveries",
       {"times a diverging stage is restarted with a smaller step before it fails; for a periodic section "
        "(`container.period_z_d`), also the taps allowed where the spheres jam before the period"}},
      {"packing.soft_sphere.neighbour_skin_d", {"Verlet list skin"}},
      {"packing.soft_sphere.target_void_fraction",
       {"makes the bed a periodic section (along z, no floor) whose period is set from the spheres drawn so "
        "that its void fraction is this, exactly: total sphere volume / ((1 - target) x cross-section); instead of "
        "`container.period_z_d`; compression jams near random close packing (0.36 for equal spheres)", "1"}},
      // [packing.monte_carlo]
      {"packing.monte_carlo.temperature", {"kT / (m* g d): the barometric height in d", "d"}},
      {"packing.monte_carlo.particle_density", {"the spheres' density", "kg/m³"}},
      {"packing.monte_carlo.particle_densities", {"a mixture: one density per diameter of `particles.diameters_m`",
                                                 "kg/m³"}},
      {"packing.monte_carlo.fluid_density", {"the fluid's density (buoyancy)", "kg/m³"}},
      {"packing.monte_carlo.mixing_height_d", {"height of the lid during mixing; by default from `initial_void_fraction`"}},
      {"packing.monte_carlo.initial_void_fraction", {"void fraction below the lid during mixing", "1"}},
      {"packing.monte_carlo.mixing_cycles", {"cycles without gravity, under the lid"}},
      {"packing.monte_carlo.shakes", {"shakes after mixing"}},
      {"packing.monte_carlo.shake_amplitude_d", {"how far a shake lifts the bed"}},
      {"packing.monte_carlo.shake_dilation",
       {"a shake also stretches the bed so its top rises this many amplitudes more, every gap opening in proportion to "
        "its height (0: a rigid lift)",
        "1"}},
      {"packing.monte_carlo.settling_cycles",
       {"cycles after the last shake; on a periodic section (`container.period_z_d`), the cap on the cycles that "
        "compress it"}},
      {"packing.monte_carlo.settle_block_cycles", {"when a shake has settled: cycles per block compared"}},
      {"packing.monte_carlo.settle_tolerance_d", {"when a shake has settled: largest change of the mean height"}},
      {"packing.monte_carlo.max_settle_cycles", {"when a shake has settled: cap on its cycles"}},
      {"packing.monte_carlo.target_acceptance", {"move size control: the share of moves accepted it aims at", "1"}},
      {"packing.monte_carlo.max_displacement_d", {"move size control: the largest move"}},
      // [analysis]
      {"analysis.exclude_d", {"slab left out at the floor and below the top for the central values"}},
      {"analysis.radial_bin_d", {"radial profile bin width"}},
      {"analysis.axial_bin_d", {"axial profile bin height"}},
      {"analysis.contact_tolerance_d", {"largest gap counted as a contact, in smallest diameters"}},
      {"analysis.line_intersection", {"also radial profiles by line intersection"}},
      {"analysis.line_step_d", {"line intersection: z step"}},
      // [contacts]
      {"contacts.treatment",
       {"what is done where spheres touch, so the fluid has no zero-width wedges: a cylinder bridge, a cap that cuts "
        "both, spheres shrunk or enlarged, or nothing; the default changes the solid by at most 0.5 %",
        "", kWhyContacts}},
      {"contacts.wall_treatment", {"the same for sphere-wall contacts; `same` follows `treatment`"}},
      {"contacts.at_periodic_planes",
       {"periodic section (container.period_z_d), bridges, caps and unions: what its planes do to the treated "
        "contacts they cross: `open` them (their spheres shrunk by shrink_factor, the contact left a gap; not enlarge) "
        "or `cut` them through as treated (a surface built over two periods and cut at one plane; a period of at least "
        "twice max(4 edge_length_d, 0.5) d; enlarge too). `cut` left 5-14 cells of 290 k failing checkMesh at the planes where `open` left none "
        "(docs/findings.md, 2026-12-01), so `open` is the default"}},
      {"contacts.at_clip_planes",
       {"clip window (surface.clip_window_d), bridges, caps and unions: what its planes do to the treated contacts "
        "they cross: `cut` them through as treated (the window's spheres laid out whole and their surface cut at "
        "each plane, as the slabs between pieces are; the planes go to the widest gap between the spheres' ends and "
        "the contacts' rims within clip_shift_d that keeps clip_clearance_d from the spheres' ends) or `open` them "
        "where they find no height clear of them (their spheres shrunk by shrink_factor, the contact left a gap; not "
        "enlarge). `cut` passed the surface and mesh gates on 7 windows of the default scene's bed where `open` "
        "failed 4 (docs/findings.md, 2026-12-04)",
        "", kWhyContacts}},
      {"contacts.shrink_factor", {"shrink: sphere scale", "1"}},
      {"contacts.enlarge_factor", {"enlarge: sphere scale", "1"}},
      {"contacts.enlarge_join_gap_d",
       {"enlarge: a sphere left nearer than this to a sphere or a wall is grown to join it (0 turns it off); whatever "
        "it is, a sphere left overlapping another or a wall by less than half what touching ones get is grown to that "
        "overlap: a thinner joint leaves a fluid wedge no mesh fills"}},
      {"contacts.bridge_diameter_d", {"bridge: the cylinder's diameter"}},
      {"contacts.bridge_gap_d", {"bridge: gaps below this get a bridge"}},
      {"contacts.cap_gap_d", {"cap: gaps below this are capped, leaving this gap"}},
      // [surface]
      {"surface.edge_length_d",
       {"target triangle edge; the volume mesh follows it. A mesh whose estimated memory exceeds what the machine has "
        "is refused before packing, naming the edge that would fit; once the bed is packed the estimate is made again "
        "with its narrow gaps (without cells_per_gap, with the cells graded around its contacts), printed as `mesh "
        "estimate` and kept in the report's `stages.mesh.estimate`",
        "", kWhySurface}},
      {"surface.contact_edge_length_d",
       {"edge on the loops of treated contacts; on a bridge to a wall, times the bridge's length over that of a "
        "bridge between two touching spheres (half at a flat wall, less at a concave one), so that its triangles "
        "keep their shape",
        "", kWhySurface}},
      {"surface.growth", {"growth of the edge per ring away from a contact", "1"}},
      {"surface.sphere_facets",
       {"where the spheres' vertices lie: `inscribed`, on the sphere (its flat triangles then cut off some of it: the "
        "fluid is larger by about the triangles' mean depth, edge^2 / (8 r), over the spheres' area), or `volume`, "
        "moved out along the radius so that the triangles hold each sphere's volume (the loops where a sphere meets a "
        "contact, a wall or a plane stay on it, and so do vertices in gaps narrower than their triangles' edge)"}},
      {"surface.cells_per_gap",
       {"cells across narrow gaps: where a sphere or wall faces another surface closer than this times "
        "`edge_length_d`, its edge shrinks to gap / this (not below `contact_edge_length_d`), and the volume mesh gets "
        "about this many cells across (0: none). A bed whose gaps would not fit in memory is refused after packing, "
        "before its surface, naming this key and the value that would fit",
        "1", kWhySurface}},
      {"surface.inlet_length_d", {"empty section below the bed"}},
      {"surface.outlet_length_d", {"empty section above the bed"}},
      {"surface.clip_window_d",
       {"`[bottom, top]`, heights above the floor: their planes become the inlet and outlet and cut the spheres "
        "crossing them, instead of the empty sections"}},
      {"surface.clip_shift_d",
       {"how far a clip plane may move to keep `clip_clearance_d` clear of every sphere's top and bottom and every "
        "bridge, cap or union; where no such height exists, the contacts the plane cuts are opened instead (their "
        "spheres shrink by `contacts.shrink_factor`; not with enlarge); the planes used and the contacts opened are "
        "in the report"}},
      {"surface.clip_clearance_d",
       {"the clearance a clip plane keeps; the planes between slabs and pieces, and a clip window's cut through "
        "contacts, keep it from every sphere's top and bottom (at its treated radius) where a height within "
        "clip_shift_d does: a = 14, N = 1e4 in 4 pieces diverged twice beside a plane 0.0017 d below a sphere's end "
        "and converged with its planes 0.005 d or more from them (docs/findings.md, 2026-12-06)"}},
      {"surface.min_angle_deg",
       {"quality gate: a surface with a smaller triangle angle fails, naming the particles nearby and writing the "
        "triangles to `bad_triangles.vtp` (0 turns it off)"}},
      // [mesh]
      {"mesh.algorithm", {"gmsh 3D algorithm tried first"}},
      {"mesh.fallback", {"retry with the other algorithm when the quality gate fails"}},
      {"mesh.max_size_d",
       {"largest cell edge; elsewhere cells follow the surface's triangles (`surface.edge_length_d`, "
        "`contact_edge_length_d`, `cells_per_gap`)",
        "", kWhyMeshSizes}},
      {"mesh.optimize", {"gmsh's tetrahedral optimiser: one pass, more while cells fail the gate", "", kWhyMeshSizes}},
      {"mesh.max_optimize_passes",
       {"optimiser passes at most; if cells still fail, HXT meshes again with its own optimiser (slower, one thread, "
        "several times the memory; skipped when that will not fit)"}},
      {"mesh.threads", {"threads, 0 for every core"}},
      {"mesh.slabs",
       {"axial slabs meshed one after the other by gmsh and joined into one conforming mesh, so gmsh's memory follows "
        "a slab, not the bed; 0: one slab per million surface triangles when `contacts.treatment` is shrink or none "
        "and there are no prism layers and no periodic planes, else 1. Under shrink or none each slab's surface is "
        "built on its own; under bridge, cap or enlarge each is cut, through the contacts the planes cross, from the "
        "surface of the spheres within a few diameters of its slab, held whole (in a box: from the whole surface); the "
        "planes keep clear of the contacts' rims where they can. No prism layers (a plane would cut them open). "
        "Slabs that cannot be cut from the bed or fail the quality gate are meshed once more with their planes moved "
        "to other gaps between the spheres' ends",
        "", kWhySlabs}},
      {"mesh.pieces",
       {"the case written in this many axial pieces, each meshed by its own Open MPI rank (`mpirun -np N bedforge "
        "piece`, started by the run) as `case/processorK` with processor patches, and solved on as many processes "
        "without decomposePar; no process holds the whole mesh; a convergence study's levels likewise; pieces that "
        "cannot be cut or fail the quality gate are meshed once more with the planes moved, as slabs are (only the "
        "planes of the piece that stopped first, when mpirun names it: a piece whose window reaches no moved plane "
        "keeps its cells). 0 or 1: one piece. Every "
        "contact treatment in a cylinder or annulus (bridges, caps and unions cut by the planes from each rank's "
        "widened window, its walls ringed there), shrink or none in a box; no prism layers, no snappyHexMesh, no "
        "`stl` or `mesh` output (there is no whole surface or mesh)"}},
      // [mesh.gate]
      {"mesh.gate.max_non_orthogonality_deg", {"quality gate: largest face non-orthogonality (checkMesh's definition)"}},
      {"mesh.gate.max_skewness", {"quality gate: largest skewness (checkMesh's definition)", "1"}},
      {"mesh.gate.max_aspect_ratio", {"quality gate: largest cell aspect ratio (checkMesh's definition)", "1"}},
      {"mesh.gate.min_volume_d3", {"quality gate: smallest cell volume"}},
      // [mesh.layers]
      {"mesh.layers.count", {"prism layers on the particle surfaces (0: none)", "", kWhyLayers}},
      {"mesh.layers.thickness_d", {"total thickness of a stack with room to grow", "", kWhyLayers}},
      {"mesh.layers.growth", {"thickness ratio of one layer to the one below it", "1", kWhyLayers}},
      {"mesh.layers.gap_fraction",
       {"largest share of the gap in front of a vertex one stack takes; where that leaves less than half of "
        "`thickness_d` there is no stack, and stacks taper to nothing where particles meet a wall, the inlet or the "
        "outlet. With a convergence study every level, the scene's own included, applies this rule at the coarsest "
        "level's lengths and scales the stacks it allows to its own, so that every level layers the same region",
        "1", kWhyLayers}},
      // [case]
      {"case.reynolds",
       {"particle Reynolds number of the superficial velocity, rho u d / mu; the flow is solved steady and laminar, "
        "and past 150 the answer says that a packed bed's flow is unsteady there (docs/reference.md)",
        "1"}},
      {"case.density_kg_m3", {"the fluid's density"}},
      {"case.viscosity_pa_s", {"the fluid's dynamic viscosity"}},
      {"case.iterations",
       {"simpleFoam's iteration cap; a solve whose residual of U or p climbs past 10 times the least it reached (or its "
        "target) is stopped sooner, its fields written there, and the run exits 3 (cases/case_runner.hpp)"}},
      {"case.residual_p",
       {"simpleFoam's convergence target for p; tighter on a periodic section, whose driving gradient settles slowly",
        "1", kWhyResiduals}},
      {"case.residual_u",
       {"the same for U; tighter on a periodic section, and its own default on cells with prism layers, where U's "
        "residual stalls near 3e-3 while dp/L has settled",
        "1", kWhyResiduals}},
      {"case.iteration_tolerance",
       {"past the residual targets the solve runs on until dp/L's estimated iteration error (from how its last changes "
        "shrank) is within this fraction of it, by at most as many iterations again; SIMPLE's own stop is written at a "
        "hundredth of the targets, where a case run by hand stops",
        "1", kWhySettled}},
      {"case.processors", {"subdomains of decomposeParDict: `Allrun -np N` runs on N of them"}},
      {"case.decomposition", {"decomposition method"}},
      {"case.format", {"polyMesh and field format"}},
      {"case.cells",
       {"the cells solved on: the dual polyhedra of gmsh's tetrahedra (as `polyDualMesh 80` makes them, about a fifth "
        "as many cells), on which the empty tube's pressure drop comes within 0.25 % of the exact one from some 20 k "
        "cells on (0.12-0.21 % high past 130 k, not converging to it); or gmsh's tetrahedra, where it reads up to 0.6 % "
        "high, not converging; slivers with two faces on a wall that turns by less "
        "than 30 deg across them are cut off the tetrahedra first (the dual around one fails checkMesh); the "
        "polyhedra are checked against checkMesh's limits "
        "(non-orthogonality below 90 deg, skewness 4, positive volumes and face pyramids) before the case is written, "
        "two cells across a failing face merged, and those that still fail said and written beside the case to "
        "`bad_polyhedra_<case>.vtk`",
        "", kWhyCells}},
      {"case.drag_by_gap_d",
       {"`[edge, ...]`, ascending, reference diameters, at most 7: the particles' patch split by the gap at each "
        "face's centre (to the nearest other sphere or wall) into `particles_gap0` (below the first edge) to "
        "`particles_gapN` (beyond the last), of the faces in the bed section, and `particles_ends` of those beyond "
        "its planes, each with its forces object, and the walls' patches at those planes (`wall_ends` beyond "
        "them), so that the report and the convergence study give the particles' drag band by band and the walls' "
        "in the section: where the discretisation error sits. The cells and the flow "
        "are the same as without it; not with `mesh.pieces` > 1 or `case.mesher = \"snappy\"`"}},
      {"case.section_exclude_d",
       {"the bed section of the pressure drop: floor (or clip inlet) + this to bed top (or clip outlet) - this"}},
      {"case.walls",
       {"velocity on the container's walls; `slip` walls are mirror planes, so a box stands for a slab of an "
        "unbounded bed or a column of an array (compared with Eisfeld & Schnitzlein without their wall term). A column "
        "of equal spheres spaced by the side of a square box with slip walls, at Re_p <= 0.01, a solid fraction Zick & "
        "Homsy (1982) tabulate, `contacts.treatment = \"none\"` and a section a whole number of cells long is compared "
        "with the simple cubic array's Stokes drag instead (`scenes/examples/simple_cubic_verification.toml`)"}},
      {"case.mesher",
       {"what makes the cells solved on: gmsh, the mesh stage; or snappyHexMesh in the case's Allrun, from the fluid "
        "surface, on every process (no gmsh mesh). Not validated: at its defaults on the a = 14, N = 1e4 bridged bed "
        "its cells lost 19.5 % of the fluid, failed checkMesh and gave dp/L 3.5 x Eisfeld & Schnitzlein "
        "(docs/mesh_case_benchmark.md); a set-up to start snappyHexMesh from, whose cells you must check. Its "
        "cells keep only the fluid connected to the inside point: the report's `flow.mesh.volume_lost` says how much "
        "they miss, and a run whose cells miss the inlet or outlet stops with exit status 3"}},
      {"case.snappy",
       {"also write the snappyHexMesh set-up (with gmsh's cells, `./Allrun -snappy` uses it); true with "
        "`mesher = \"snappy\"`"}},
      {"case.snappy_cell_d", {"snappyHexMesh's background cell"}},
      {"case.snappy_level", {"snappyHexMesh's refinement levels at walls and particles"}},
      {"case.run",
       {"run Allrun, read the pressure drop into the report and end the run in its answer (best estimate, band, "
        "correlation; pressure_drop.svg); without OpenFOAM the case is written, not solved, and the run exits with "
        "status 4. The report's `flow.allrun_steps` gives each step's wall time and peak memory",
        "", kWhyAnswer}},
      // [case.convergence]
      {"case.convergence.levels",
       {"meshes of the convergence study, the scene's own the finest (0: none): the flow solved again on coarser "
        "meshes of the same bed for the pressure drop's discretisation error. From the finest three the apparent "
        "order, the Richardson-extrapolated dp/L and the grid convergence index (Celik et al. 2008), or why none "
        "applies; with four or more, also a least-squares power law (Eca & Hoekstra 2014). Kept in the report's "
        "`stages.case.convergence`; `tools/plot_bed.py DIR` draws it. Needs `case.run`",
        "", kWhyAnswer}},
      {"case.convergence.ratio",
       {"cell size of each coarser level over the finer one's, measured on the cells solved on: every mesh length "
        "scaled (and `cells_per_gap` divided) by the factor that gets there, searched to within 3 %",
        "1", kWhyAnswer}},
      // [outputs]
      {"outputs.files",
       {"the files a run writes: bed.csv, bed.vtp, the analysis, the STL surfaces, fluid.msh, the OpenFOAM case; each "
        "brings the stages it needs"}},
  };
  return meanings;
}

std::string key_unit(const std::string& key) {
  const auto& meanings = scene_key_meanings();
  if (auto it = meanings.find(key); it != meanings.end() && !it->second.unit.empty())
    return it->second.unit == "1" ? "" : it->second.unit;
  for (const auto& [suffix, unit] : kSuffixUnits)
    if (key.ends_with(suffix)) return unit;
  return "";
}

std::string heading_anchor(const std::string& heading) {
  std::string anchor;
  for (unsigned char c : heading) {
    if (std::isalnum(c) || c == '_' || c == '-') anchor += static_cast<char>(std::tolower(c));
    else if (c == ' ') anchor += '-';
  }
  return anchor;
}

std::string scene_reference_markdown(const SceneSchema& schema) {
  const auto& meanings = scene_key_meanings();
  std::string out =
      "Every key a scene may set, by section: its type, unit (d: particle diameters, the smallest for a mixture), "
      "default, allowed values and meaning. Generated by `bedforge scene-keys` from the schema the scene readers "
      "record (which also makes `bedforge <command> --help`) and the meanings in pipeline/scene_reference.cpp; a "
      "test fails when this page is stale. Why a default is what it is: [defaults.md](defaults.md).\n";
  // Sections in the order a scene is read, each before its sub-sections; keys by name within.
  std::vector<std::string> keys;
  for (const auto& entry : schema) keys.push_back(entry.first);
  const auto place = [](const std::string& key) {
    const std::size_t dot = key.rfind('.');
    const std::string top = key.substr(0, key.find('.'));
    const auto& sections = scene_sections();
    return std::tuple(std::find(sections.begin(), sections.end(), top) - sections.begin(), key.substr(0, dot),
                      key.substr(dot + 1));
  };
  std::stable_sort(keys.begin(), keys.end(), [&](const auto& a, const auto& b) { return place(a) < place(b); });
  std::string section;
  for (const std::string& key : keys) {
    const KeySpec& spec = schema.at(key);
    const auto it = meanings.find(key);
    if (it == meanings.end()) throw std::logic_error("scene key " + key + " has no meaning in scene_reference.cpp");
    const std::size_t dot = key.rfind('.');
    const std::string key_section = key.substr(0, dot), leaf = key.substr(dot + 1);
    if (key_section != section) {
      section = key_section;
      out += fmt::format("\n## [{}]\n\n| key | type | unit | default | allowed | meaning |\n|---|---|---|---|---|---|\n",
                         section);
    }
    const KeyMeaning& m = it->second;
    const std::string why = m.why.empty() ? "" : fmt::format(" ([why](defaults.md#{}))", heading_anchor(m.why));
    out += fmt::format("| `{}` | {} | {} | {} | {} | {}{} |\n", leaf, spec.type, key_unit(key), spec.fallback,
                       spec.allowed, m.meaning, why);
  }
  return out;
}

std::string scene_reference_page(const std::string& version, const std::string& date) {
  return fmt::format("# Scene keys\n\n_Generated by `bedforge scene-keys` (bedforge {}, {})._\n\n{}", version, date,
                     scene_reference_markdown(scene_schema()));
}

}  // namespace bedforge::pipeline
