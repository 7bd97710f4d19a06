#pragma once
#include <nlohmann/json.hpp>

#include <vector>

#include "core/scene_section.hpp"
#include "meshing/volume/poly_mesh.hpp"
#include "meshing/surface/triangle_mesh.hpp"

namespace bedforge::meshing {

// Prism layers on the particle surfaces, scene section [mesh.layers]. Lengths in reference
// diameters d. Each vertex of the `particles` patch is pushed into the fluid along its normal
// by a stack of `count` layers growing by `growth`; the tetrahedra then fill the rest. Where
// there is no room the stack thins: it takes at most `gap_fraction` of the gap in front of it
// and leaves the tetrahedra at least one local surface edge of it (none where that is under
// half of `thickness_d`: narrow gaps keep their tetrahedra), changes by at most half the
// distance between neighbouring vertices (so side faces stay upright), and is zero on the
// edges the particles share with other patches (a bridge's foot on a wall, a sphere cut by the
// inlet). Next to a stack of no height prisms collapse to pyramids and tetrahedra.
struct PrismLayerParams {
  int count = 0;              // layers; 0: none
  double thickness_d = 0.02;  // total thickness of a stack with room to grow
  double growth = 1.2;        // each layer this much thicker than the one below it
  double gap_fraction = 0.2;  // largest share of the gap in front of a vertex one stack takes
  // Not a scene key: the room rule above is applied with the thickness and the local edge this
  // many times larger, and the stacks it allows shrunk back by the same factor. A convergence
  // study sets it so that every level decides its stacks as its coarsest level would
  // (pipeline::layers_for_study): the same region layered on every level, every stack scaled
  // with the level's lengths, a systematic refinement. 1: the rule at the level's own lengths.
  double room_scale = 1.0;
};
PrismLayerParams read_prism_layer_params(SceneSection& layers);
nlohmann::json to_json(const PrismLayerParams& p);

struct PrismLayers {
  // The fluid surface with every layered vertex moved to the top of its stack: the boundary the
  // tetrahedra fill. Same triangles, vertices and patches as the input.
  TriangleMesh top;
  // Points below the tops of the stacks; point index i >= top.points.size() of `cells` and
  // `particle_faces` is below[i - top.points.size()], a smaller index a point of `top`.
  std::vector<Eigen::Vector3d> below;
  std::vector<VolumeCell> cells;     // prisms, and pyramids and tetrahedra where stacks collapse
  std::vector<Face> particle_faces;  // the particle triangles at the feet of the stacks: the wall
  nlohmann::json report;
};

// Layers on the `particles` patch of `surface` (closed, labelled, in m, normals out of the
// fluid); d_ref (m) scales the parameters. The layers are checked as OpenFOAM would: every face
// pyramid of every layer cell positive and the tops of the stacks crossing no other surface;
// stacks that fail are halved, and collapsed when thinner than 2 % of the target, until none
// fails. ConvergenceError when 30 rounds do not clear them.
PrismLayers build_prism_layers(const TriangleMesh& surface, double d_ref, const PrismLayerParams& p);

}  // namespace bedforge::meshing
