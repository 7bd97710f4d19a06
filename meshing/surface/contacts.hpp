#pragma once
#include <nlohmann/json.hpp>

#include <limits>
#include <string>
#include <vector>

#include "core/bed.hpp"
#include "meshing/surface/fluid_surface.hpp"
#include "meshing/surface/primitives.hpp"
#include "meshing/surface/wall_mesh.hpp"

namespace bedforge::meshing {

// The planes that bound the fluid domain below and above (m). With `clip` they cut the bed (a
// height window of it); otherwise no sphere may reach them.
struct DomainPlanes {
  double z0 = 0.0, z1 = 0.0;
  bool clip = false;
};

// The bed after its contact treatment, as pieces the surface is meshed from. Lengths in m.
struct TreatedBed {
  std::vector<char> kept;                         // per sphere: false when wholly outside a clip window (not meshed)
  std::vector<double> radius;                     // per sphere, after shrink or enlarge
  std::vector<std::vector<SphereCut>> cuts;       // per sphere: where its mesh stops
  std::vector<std::vector<std::string>> cut_names;  // per sphere and cut, for error messages ("sphere 7", "wall")
  std::vector<TriangleMesh> parts;                // cap disks and bridges, normals out of the solid
  // Where the bed meets each wall of the container: cylinder {wall}, annulus {wall, inner
  // wall}, box {x min, x max, y min, y max}; and where spheres cross the clip planes.
  std::vector<std::vector<WallHole>> wall_holes;
  std::vector<WallHole> inlet_holes, outlet_holes;
  DomainPlanes planes;                            // as used: clip planes move off near-tangent spheres and contacts
  double solid_volume = 0.0;                      // exact volume of the treated solid (m^3)
  // Of the treated solid and of the untreated spheres, the parts between two heights, when
  // treated_solid_between asked (m^3; NaN otherwise).
  double solid_volume_between_m3 = std::numeric_limits<double>::quiet_NaN();
  double untreated_volume_between_m3 = std::numeric_limits<double>::quiet_NaN();
  long thin_gap_contacts = 0;                     // contacts left as thin gaps (shrunk, or untreated)
  // Narrowest gap left between a sphere and a cylinder wall around the fluid (m): that wall's
  // facets lie inside it, towards the spheres (an annulus's inner wall's lie away from them).
  // With clip planes, the narrower of the window's and the whole bed's.
  double min_concave_wall_gap = 0.0;
  double bed_min_concave_wall_gap = 0.0;          // the whole bed's, without the window's opened contacts
  nlohmann::json report;                          // contacts treated, volume and area change, gaps, angles
};

// Contact treatment (section [contacts]) of `bed` in a cylinder, annulus or walled box whose
// fluid domain runs between `planes`. A clip plane moves (by up to surface.clip_shift_d) to the
// height nearest the one asked for that lies surface.clip_clearance_d clear of every sphere's
// top and bottom and of every treated contact; spheres crossing it are cut there, spheres and
// contacts beyond it are left out. Where no height is clear of the treated contacts, the plane
// keeps clear of the spheres' ends (at their radius and shrunk by contacts.shrink_factor) and
// the contacts near it are opened: both spheres shrink by shrink_factor and the contact is left
// as a gap (not with enlarge, whose grown neighbours a shrunk sphere would still overlap).
// Pairs and wall contacts closer than the treatment's gap tolerance get its geometry; every
// other gap is left as it is and the narrowest is reported. Volumes and areas are exact
// (closed forms, or quadrature to 1e-10 for bridges to a curved wall and spheres crossing one).
// InputError naming the particles when the treatment cannot give a valid solid: contacts left
// touching, overlaps too deep, a bridge through a third sphere, a sphere or bridge reaching an
// unclipped inlet or outlet plane, no clear height for a clip plane, an opened contact still
// overlapping, cuts on one sphere that overlap, a periodic box.
TreatedBed treat_contacts(const Bed& bed, const SurfaceParams& p, DomainPlanes planes);

// treat_contacts of `bed` in a domain its planes bound without cutting it (none reaches them),
// with the parts of the treated solid and of the untreated spheres between the heights z1 < z2
// (m) measured too (TreatedBed::solid_volume_between_m3, untreated_volume_between_m3; the
// report's "contacts_treated_between" counts the contacts whose geometry reaches between them, as
// "contacts_treated" counts all), exactly
// as the whole: the spheres and caps in closed form or by quadrature to 1e-9, bridges to a
// curved wall by quadrature (a kink where a generator meets a height: about 1e-6 of theirs).
TreatedBed treat_contacts_measured_between(const Bed& bed, const SurfaceParams& p, double z1, double z2);

struct UnwrappedSection;  // clip_planes.hpp
// The same for a periodic section laid out by unwrap_periodic_section: its spheres cut by the
// two planes, and each loop on the upper plane its twin's on the lower one moved up a period
// (outlet_holes left empty: the outlet is meshed as a copy of the inlet). A bridge or cap that
// a plane crosses (within surface.clip_clearance_d) is opened as a clip window opens it (its
// spheres, and their images a period away, shrink by contacts.shrink_factor and it is left as a
// gap); report "periodic_planes_m" counts them. (contacts.at_periodic_planes = "cut" cuts them
// through instead: build_cut_periodic_surface.)
TreatedBed treat_periodic_section(const UnwrappedSection& section, const SurfaceParams& p);

}  // namespace bedforge::meshing
