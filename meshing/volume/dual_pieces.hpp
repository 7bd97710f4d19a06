#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "meshing/volume/poly_mesh.hpp"

namespace bedforge::meshing {

// The polyhedral dual of a mesh made in axial pieces (slabs of tetrahedra, one per rank), with
// whole cells across the planes between pieces. The dual cell of a point on a plane takes
// tetrahedra from both slabs; cut in two halves, one per piece, a face between halves failed
// checkMesh (skewness 4.2, an inverted face pyramid). So each piece also reads its neighbours'
// tetrahedra next to their shared plane (a PlaneLayer, written by the neighbour's rank), makes
// the dual of its slab with them, and keeps the cells of its own points, the plane's points
// going to the piece below. The faces between its cells and a neighbour's are then the same
// faces of the same tetrahedra on both sides: processor patches that match point for point,
// and the pieces' cells together are the whole mesh's dual.

// A slab's tetrahedra within rings of points of one of its planes: those touching the plane, then
// those touching their points, and so on. Three rings: with two, every boundary face around a
// point next to the plane is there, which the dual needs to mark that point's feature edges as
// the whole mesh would, so the piece's own cells are the whole mesh's; the third keeps the
// layer's edge (whose meeting with a wall the dual takes for a feature) away from the points
// next to those, so that the neighbour's cells across the plane are the whole mesh's too, and
// the faces between them are judged as checkMesh judges them (check_polyhedra).
struct PlaneLayer {
  std::vector<Eigen::Vector3d> points;  // m
  std::vector<VolumeCell> cells;        // tetrahedra, into points
  std::vector<Face> boundary;           // the domain's boundary faces of these cells, and their
                                        // faces towards the rest of the slab (patch kLayerEdge)
  std::vector<int> patch;               // per boundary face, into names
  std::vector<std::string> names;       // patch names
  std::string tag;                      // the run that wrote it (Open MPI's job), "" outside one
};
inline constexpr const char* kLayerEdge = "layer_edge";

// The layer of `slab` (a PolyMesh of tetrahedra) at its patch `plane` ("inlet" or "outlet"),
// `rings` rings deep (3, what the dual and its gate need; more takes more of the slab, all of it
// at last).
// std::runtime_error when the slab has no such patch.
PlaneLayer plane_layer(const PolyMesh& slab, const std::string& plane, int rings = 3);

// All of a slab's tetrahedra and boundary faces as a layer (no kLayerEdge faces), and the slab
// back from one (its cells renumbered as poly_mesh_from_cells numbers them): what a piece keeps
// on disk so that a rerun need not mesh it again.
PlaneLayer whole_slab(const PolyMesh& slab);
PolyMesh slab_of(const PlaneLayer& whole);

// A layer as a binary file (written through a temporary file and a rename, so a reader never
// sees half of one) and read back, whole or its tag alone (which run wrote it, without reading
// its cells); InputError naming the file when it cannot be read.
void write_plane_layer(const std::filesystem::path& path, const PlaneLayer& layer);
PlaneLayer read_plane_layer(const std::filesystem::path& path);
std::string read_plane_layer_tag(const std::filesystem::path& path);

// A slab with its neighbours' layers joined on: the tetrahedra of all three, the planes between
// them internal, the layers' faces towards the rest of their slabs in patch kLayerEdge (last).
//   slab    PolyMesh of tetrahedra of piece k, m
//   below   layer of piece k - 1 at its outlet (null for the first piece); above: of piece k + 1
//           at its inlet (null for the last)
// `side` per point of `mesh`: -1 for the piece below (its layer's points and the slab's inlet
// points, when below is given), 0 for the piece's own, +1 for the piece above (the points of the
// plane between them are the piece's own). std::runtime_error when a layer's points on the
// shared plane are not the slab's, bit for bit (a layer of another run or another bed).
struct SlabWithLayers {
  PolyMesh mesh;
  std::vector<int> side;
};
SlabWithLayers slab_with_layers(const PolyMesh& slab, const PlaneLayer* below, const PlaneLayer* above);

// Each tetrahedron's centroid from its points in the order of their coordinates, so that two
// pieces holding the same tetrahedron (numbered differently) get the same centre bit for bit:
// the points of their shared faces are then the same on both sides. (OpenFOAM's centre of a
// tetrahedron is its centroid, to rounding.)
std::vector<Eigen::Vector3d> tetrahedron_centroids(const PolyMesh& mesh);

// The dual of a slab with its layers cut to piece `piece` of `pieces`: the cells of the points
// with side 0, renumbered in order, their boundary faces in the slab's patches (kLayerEdge
// dropped, inlet and outlet kept even when empty, so that every piece lists the same patches),
// and their faces towards the pieces below and above as processor patches
// procBoundary<piece>to<piece-1> and procBoundary<piece>to<piece+1>, last. A shared patch's faces
// in the order of their points' coordinates (sorted), each face pointing out of its own cell and
// starting at its least point: face k of one side is face k of the other, its points reversed
// from the same 0th, as decomposePar writes them.
//   dual         dual_mesh of SlabWithLayers::mesh with tetrahedron_centroids
//   cell_points  dual_mesh's cell_points
//   side         SlabWithLayers::side
// std::runtime_error when a kept cell has a face on kLayerEdge (a layer too thin), or a face
// towards a side that is not a neighbour.
PolyhedralMesh dual_piece(const PolyhedralMesh& dual, const std::vector<int>& cell_points, const std::vector<int>& side,
                          int piece, int pieces);

}  // namespace bedforge::meshing
