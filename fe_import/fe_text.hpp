/// @file
/// What the readers of finite element exports (fe_import/fe_abaqus.hpp, fe_import/fe_ansys.hpp) share:
/// a text file read line by line whose errors name the file and the line, number fields,
/// the sparse symmetric matrices (coordinate entries, checked for symmetry and duplicates)
/// and the checks of the assembled body data. docs/fe-import.md.
#pragma once

#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "bodies/fe_body_data.hpp"

namespace flexmbd::feread {

/// A matrix is symmetric when |A_ij - A_ji| <= kSymmetryTolerance max |A|: the exports
/// print 16 significant digits (Abaqus, Ansys), so a symmetric matrix differs by the
/// round-off of its printing, 1e-16 of the entry; 1e-8 also admits codes that print 9
/// digits, while a wrong or missing entry differs by the entry itself.
constexpr double kSymmetryTolerance = 1e-8;

/// A text file read line by line; every error names the file and the line.
class TextFile {
 public:
  /// @throws InputError naming the file if it cannot be opened.
  explicit TextFile(std::string path);
  /// The next line (without its line end; "\r\n" accepted) or false at the end.
  bool next(std::string& line);
  int lineNumber() const { return line_; }
  const std::string& path() const { return path_; }
  /// @throws InputError "<file>, line <n>: <what>" (the current line).
  [[noreturn]] void fail(const std::string& what) const;
  /// @throws InputError "<file>, line <line>: <what>".
  [[noreturn]] void failAt(int line, const std::string& what) const;

 private:
  std::string path_;
  std::ifstream in_;
  int line_ = 0;
};

/// The fields of `line` separated by any of `separators`, each trimmed of blanks; empty
/// fields are kept except one after a trailing separator ("1, 2," has two fields).
std::vector<std::string> splitFields(const std::string& line, const std::string& separators);
/// The line without leading and trailing blanks (spaces, tabs).
std::string trimmed(const std::string& s);

/// A finite real number filling the whole field ("1.5e-3"; with `decimalComma` also
/// "1,5e-3", German-locale Ansys output). @throws InputError at the file's current line
/// naming `what` and the field.
double realField(const TextFile& f, const std::string& field, const std::string& what, bool decimalComma = false);
/// An integer filling the whole field. @throws InputError as realField.
long integerField(const TextFile& f, const std::string& field, const std::string& what);

/// One stored entry of a sparse matrix: 0-based row and column, and the line it came from.
struct MatrixEntry {
  int row = 0;
  int col = 0;
  double value = 0.0;
  int line = 0;
};

/// How a file stores a symmetric matrix.
enum class SymmetricStorage {
  Both,   ///< both triangles (Abaqus .mtx): checked A_ij = A_ji to kSymmetryTolerance
  Lower,  ///< the lower triangle only (MatrixMarket "symmetric"): row >= column required
  Upper,  ///< the upper triangle only (CalculiX .sti, .mas): row <= column required
};

/// The n x n symmetric matrix of `entries`, both triangles stored.
/// @throws InputError naming `path`, the line and what was expected: an entry outside
/// n x n, an entry given twice, an upper entry in Lower storage (a lower one in Upper),
/// A_ij != A_ji (Both).
SpMat assembleSymmetric(const std::vector<MatrixEntry>& entries, int n, SymmetricStorage storage,
                        const std::string& path);

/// The n x n symmetric matrix of the file `path` of lines "row column value" (1-based,
/// blanks, tabs or commas between; blank lines skipped): Abaqus .mtx (Both), CalculiX
/// .sti and .mas (Upper). `dofWhat` says where the n DOF come from, for the messages
/// ("of the nodes (3 per node)").
/// @throws InputError naming the file, the line and what was expected: a line of other
/// than 3 fields, a row or column that is not an integer from 1 to n, a value that is not
/// a finite real, no entries, and assembleSymmetric's errors.
SpMat readRowColumnMatrix(const std::string& path, int n, SymmetricStorage storage, const std::string& dofWhat);

/// The fields of a line separated by blanks or tabs (runs count as one), none empty.
std::vector<std::string> words(const std::string& line);
/// The fields of a matrix line separated by blanks, tabs or commas (runs count as one),
/// none empty: "1, 2, 3.5" and "1 2 3.5" alike.
std::vector<std::string> matrixFields(const std::string& line);
/// Node label -> index into d.nodeIds.
std::map<long, int> labelIndex(const FeBodyData& d);

/// "x", "y", "z", "rotation x", "rotation y", "rotation z": the direction of `f`, for messages.
std::string dofName(const FeDof& f);

/// The checks every reader ends with: one row per (node, direction), each once, every node
/// with its three translations and either none or all three rotations, matrices
/// numDofs() x numDofs(), every DOF with a positive stiffness diagonal (else a node outside
/// every element, or matrices of another mesh), positive total mass r_k^T M r_k in each
/// direction k (r_k the rigid translation along k).
/// @throws InputError naming `massPath` or `stiffnessPath` and what was expected.
void checkBodyData(const FeBodyData& d, const std::string& massPath, const std::string& stiffnessPath);

}  // namespace flexmbd::feread
