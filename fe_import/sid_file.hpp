/// @file
/// The text file of the Standard Input Data of a flexible body (SID, Wallrapp1994; the
/// ".SID_FEM" files of FEMBS and of the Modelica and Python SID tools): bodies/sid_data.hpp
/// holds the data, this file its reading and writing. Layout, block by block:
/// docs/fe-import.md, "SID".
#pragma once

#include <iosfwd>
#include <string>

#include "bodies/sid_data.hpp"

namespace flexmbd {

/// Writes `sid` as text: part / new modal / refmod / new frame (the nodes) / the Taylor
/// blocks / end modal / end part. Every number with 17 significant digits (a round trip
/// is exact); entries that are zero are left out (a reader takes an entry not given as
/// zero), M0 stored as its structure says (the lower triangle of a symmetric one).
void writeSid(const SidData& sid, std::ostream& out);
/// @throws InputError naming `path` if it cannot be written.
void writeSidFile(const SidData& sid, const std::string& path);

/// Reads a SID text file strictly: every block opened and closed by name ("end <name>",
/// names compared without case), every key known, each Taylor object's header (order,
/// nrow, ncol, structure; nq from order 1, nqn at order 2) before its entries, every entry
/// inside the object's size and its structure (no upper entry in a symmetric M0, none off
/// the diagonal of a diagonal one), none given twice, mode names ielastq(1..nelastq) each
/// once. Blank lines and lines starting with '!' or '#' are skipped.
/// @throws InputError "<file>, line <n>: <what was wrong; what was expected>".
SidData readSidFile(const std::string& path);

}  // namespace flexmbd
