#pragma once
#include <Eigen/Core>

#include <filesystem>
#include <string>

#include "core/bed_io.hpp"

namespace bedforge {

// Beds written by DEM codes, read into bedforge's frame (container axis along z through the
// origin, floor at z = 0, metres).
//
// Formats:
//   xyzd         rows `x y z d` (read_bed_text: any of , ; tab or space between fields)
//   lammps-dump  a LAMMPS or LIGGGHTS text dump (`dump custom ... id type x y z radius`): the
//                LAST snapshot in the file is read, the settled bed; columns x|xu|xs|xsu
//                (scaled coordinates of an orthogonal box are unscaled with its bounds) and
//                radius or diameter; a box periodic on some side (`ITEM: BOX BOUNDS pp pp pp`)
//                becomes the bed's container, a box with those sides periodic (and an axial
//                period when z is), in bedforge's frame: centred in x and y, z from its lower bound
//   yade         yade.export.text / textExt output: an optional `#format x_y_z_r` line
//                (x_y_z_r, x_y_z_r_matId, x_y_z_r_attrs or id_x_y_z_r_matId), then rows with
//                the RADIUS in the fourth place
// Inputs:
//   path       the file
//   to_metres  the file's length unit in metres (1e-3 for millimetres)
//   origin_m   the point of the file's frame, in metres, that becomes bedforge's origin (a
//              point on the container axis at the floor); subtracted from every centre
// Output: the bed (container null unless the file is bedforge's own CSV or a periodic dump)
// and a header with what the file said about itself (LAMMPS: the timestep and snapshot count;
// Yade: the format).
// InputError names the file, the line and what was expected.
enum class BedFileFormat { xyzd, lammps_dump, yade };
BedFileFormat bed_file_format(const std::string& name);  // "xyzd" | "lammps-dump" | "yade"
const char* bed_file_format_name(BedFileFormat format);
ImportedBed read_bed_file(const std::filesystem::path& path, BedFileFormat format, double to_metres,
                          const Eigen::Vector3d& origin_m = Eigen::Vector3d::Zero());

// The two DEM readers, for direct use; read_bed_file dispatches to them.
ImportedBed read_lammps_dump(const std::filesystem::path& path, double to_metres);
ImportedBed read_yade_text(const std::filesystem::path& path, double to_metres);

}  // namespace bedforge
