#pragma once
#include <cstddef>
#include <nlohmann/json.hpp>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "core/bed.hpp"
#include "meshing/surface/contacts.hpp"
#include "meshing/surface/fluid_surface.hpp"

namespace bedforge::meshing {

// A contact of a bed of n spheres as one number: spheres i < j, or sphere i and wall w as
// j = n + w; and back.
inline long long contact_key(std::size_t i, std::size_t j, std::size_t n) {
  return static_cast<long long>(i) * (n + 8) + j;
}
inline std::pair<std::size_t, std::size_t> contact_of(long long k, std::size_t n) {
  return {static_cast<std::size_t>(k) / (n + 8), static_cast<std::size_t>(k) % (n + 8)};
}

// What each treated contact occupies in z (m), by contact key: a clip plane must keep clear of it.
using ContactExtents = std::unordered_map<long long, std::pair<double, double>>;

// Contacts a clip plane cuts through, opened instead of treated: their spheres shrink by
// contacts.shrink_factor and the contacts are left as gaps.
struct ClipOpening {
  std::vector<char> spheres;              // per sphere
  std::unordered_set<long long> contacts;  // by contact_key
};

struct ClipPlacement {
  DomainPlanes planes;     // the asked window's planes, each moved clear of the bed
  ClipOpening opening;     // empty where both planes found room between the contacts
  nlohmann::json report;   // per plane: asked_d, used_d, clearance_d, contacts_opened
};

// Places the clip planes of `asked` (m) within surface.clip_shift_d of where they were asked,
// surface.clip_clearance_d clear of every sphere's top and bottom (`radius`: the treated radii,
// m) and of every treated contact (`extents`, from treating the whole bed). A packed bed has
// bridges or caps at every height, so a plane often finds no height clear of them; it then keeps
// clear of the spheres' tops and bottoms only (at either radius) and the contacts near it are
// opened (not with enlarge, whose grown neighbours a shrunk sphere would still overlap).
// InputError naming the key when no height will do.
ClipPlacement place_clip_planes(const Bed& bed, const SurfaceParams& p, DomainPlanes asked,
                                const std::vector<double>& radius, const ContactExtents& extents);

// How far (m) from a plane a treated contact's z extent may reach and be opened there: the
// plane's surface.clip_clearance_d plus how far a contact's geometry moves when its spheres
// shrink by contacts.shrink_factor (for the bed's largest sphere).
double opening_reach(const Bed& bed, const SurfaceParams& p);
// True when a contact whose geometry spans `range` (z, m) comes within `reach` (m) of the plane z.
inline bool reaches_plane(const std::pair<double, double>& range, double z, double reach) {
  return range.first < z + reach && range.second > z - reach;
}

// InputError naming the key when `p` treats contacts in a way a periodic section cannot take
// (enlarge, unless contacts.at_periodic_planes = "cut": see treat_periodic_section); the scene
// reader calls it too, before any work.
void refuse_treatments_across_periodic_planes(const SurfaceParams& p);
// True when `p` bridges or caps contacts (of pairs or walls): treat_periodic_section opens those
// a periodic plane crosses (unless build_cut_periodic_surface cuts them through).
bool opens_contacts_at_periodic_planes(const SurfaceParams& p);

// How far (d) a window is widened before its surface is cut at a plane through treated
// contacts (a slab's, a periodic section's): a sphere crossing a plane, its neighbours (whose
// contacts shape its cuts) and theirs, and the surfaces its narrow-gap spacing sees
// (surface.cells_per_gap edges): 3 largest diameters plus that length and surface.clip_shift_d.
// Within it both windows of a plane hold the same spheres, contacts and cuts.
double piece_margin_d(const Bed& bed, const SurfaceParams& surface);

// A long bed is surveyed window by window, so that no process treats all its contacts at once
// (the launching process of a run in pieces: 16 MB per 1000 spheres with bridges, docs/findings.md
// 2026-12-01): the heights (m), from -inf to +inf, between which about `spheres` sphere centres
// lie each (just -inf and +inf on a bed of no more than twice that). Each stretch is treated with
// the spheres within piece_margin_d of it (window_for_cuts), which hold every contact of its own.
inline constexpr std::size_t kSpheresPerSurveyWindow = 4000;
std::vector<double> survey_stretches(const Bed& bed, std::size_t spheres);

// The heights (m) a plane cut through `bed`'s treated contacts keeps as clear of as it can: the
// highest and lowest point of every loop where a treated contact meets a sphere (bridges' and
// caps' rims, at the wall too; enlarged spheres' unions) and the treated spheres' ends. Where a
// plane passes near one, it meets the surface nearly tangent and the cut leaves slivers (cells
// failing checkMesh's skewness beside a periodic slice's rims 0.0002 and 0.003 d from its plane,
// docs/findings.md, 2026-12-01), or a wall ring there moves a loop's vertex.
// Treated window by window (survey_stretches) on a bed of more than twice `spheres_per_window`.
std::vector<double> treated_heights(const Bed& bed, const SurfaceParams& p,
                                    std::size_t spheres_per_window = kSpheresPerSurveyWindow);

// The heights (d above the floor, sorted) a plane between slabs or a clip plane keeps clear of.
// `all`: the spheres' tops and bottoms at their own and their shrunk radius, and, for a plane cut
// through the treated contacts (`through_contacts`), treated_heights too. `sphere_ends`: the
// tops and bottoms of their surface (at the shrunk radius under shrink, else their own), of which
// a plane keeps surface.clip_clearance_d where it can, as a periodic section's planes do: a plane
// nearer a sphere's end leaves a film of fluid between them that the mesh must fill (a = 14,
// N = 1e4 in 4 pieces: a plane 0.0017 d below a sphere at the wall, over a gap of 0.07 d to the
// sphere below it, is where that bed's solve turned back, twice; docs/findings.md, 2026-12-06).
struct ClearHeights {
  std::vector<double> all, sphere_ends;
};
ClearHeights plane_clear_heights_d(const Bed& bed, const SurfaceParams& p, bool through_contacts);
// The middle of the widest interval between successive `heights.all` whose middle lies within
// `shift` of `asked` and at least `clearance` from every one of `heights.sphere_ends`, leaving
// out the interval that holds `avoid` (NaN: none); of all intervals within `shift` where none is
// that clear of the ends; `asked` itself when there is no interval: where a plane meets the
// surface at its widest angles, away from the near-tangent cuts that leave slivers.
double widest_interval_middle(const ClearHeights& heights, double asked, double shift, double avoid, double clearance);

// A window of `bed` whose surface is cut at planes inside it through its treated contacts (a
// slab's or a piece's, a periodic section's). Its own clip planes must cut no contact, which a
// plane through a packed bed cannot promise (a bed of a = 14 had no height 0.005 d clear of
// every sphere's end within 0.25 d, and the a = 5 bed enlarged none clear of its unions within
// 1 d, which cannot be opened): so the window holds, whole, only the spheres whose centres lie
// from `lo` to `hi` (m), and its planes lie half a largest diameter beyond their ends, where they
// cut nothing; on a side where `lo` or `hi` is infinite, the plane is `p`'s own (the scene's
// inlet or outlet, or its clip plane). Its lengths in d are the bed's (Bed::reference_diameter_m),
// and its walls are ringed at `rings_d` (d above the floor; curved walls with the edge of the whole
// bed's narrowest wall gap, so that every window of one bed rings a plane with the same vertices:
// p.ring_wall_gap_m when given (FluidDomainProfile::bed_wall_gap_m; a rank is handed it, and
// treats only its window), else found by treating the whole bed).
struct CutWindow {
  Bed bed;
  SurfaceParams surface;
  std::vector<std::size_t> numbers;  // per sphere of the window: its index in `bed`
};
CutWindow window_for_cuts(const Bed& bed, const SurfaceParams& p, double lo, double hi, std::vector<double> rings_d);
// window_for_cuts's window for a survey of its treatment only: its walls not ringed, so the
// whole bed's wall gap is not looked for.
CutWindow survey_window(const Bed& bed, const SurfaceParams& p, double lo, double hi);
// The spheres of `bed` whose centres lie from `lo` to `hi` (m), whole and in their order, as a
// window of it (window_for_cuts without its planes and rings): surface `p` with the whole bed's
// narrowest wall gap in ring_wall_gap_m, as given or found by treating the whole bed.
CutWindow spheres_between(const Bed& bed, const SurfaceParams& p, double lo, double hi);
// `message` (an error of the window's surface) with each "sphere K" and "particle K" numbered
// as in the bed the window was taken from, so that it names the spheres a user can find.
std::string in_bed_numbers(const CutWindow& window, const std::string& message);

// A bed periodic along z (container.axial_period() = H > 0) laid out for meshing between two
// planes a period apart, z0 and z0 + H: z0 is, of the middles of the 64 widest intervals between
// the spheres' ends (at their radius under `p`'s treatment) over one period that lie
// surface.clip_clearance_d clear of them, the one whose cut circles keep the widest gap between
// each other and to the walls (the periodic faces' triangles are as narrow); each centre moved by
// a period into [z0, z0 + H), then a copy a period away of each sphere crossing a plane. The
// bed's container has no period (the copies are its images); its reference diameter is the bed's.
// twin[i]: for a sphere crossing the upper plane, the index of its copy crossing the lower one,
// whose cut loop it takes (-1 for the others). Not enlarge unless cut through
// (refuse_treatments_across_periodic_planes names the key); with bridges or caps the heights keep clear of the spheres' ends at their
// radius and shrunk by contacts.shrink_factor alike. InputError when no height lies
// surface.clip_clearance_d clear of every sphere's end.
struct UnwrappedSection {
  Bed bed;
  DomainPlanes planes;
  std::vector<int> twin;
  double clearance = 0.0;      // of the planes from the nearest sphere end (m)
  double narrowest_gap = 0.0;  // between the cut circles on the planes, and from them to the walls (m)
};
// `keep_clear` (m, any period), for a cut through the contacts: more heights (the rims of treated
// contacts, the treated spheres' ends) the plane keeps as clear of as it can: of the 64 widest
// intervals between them and the ends, the middle of the widest that lies
// surface.clip_clearance_d clear of the ends (else as without them).
UnwrappedSection unwrap_periodic_section(const Bed& bed, const SurfaceParams& p, const std::vector<double>& keep_clear = {});

}  // namespace bedforge::meshing
