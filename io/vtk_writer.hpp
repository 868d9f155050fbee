// VTK output for ParaView: one .vtu (unstructured grid, ASCII XML) per output time and
// a .pvd collection, written as the run goes (a failed run keeps what was written).
#pragma once

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/system.hpp"
#include "integrators/simulation.hpp"

namespace flexmbd {

/// Every body as poly-lines: a flexible beam body as its deformed axis (each element
/// drawn with `subdivisions` segments, point data: elastic displacement, axial force N,
/// bending moment M); a rigid body as the line through its frame origin, its centre of
/// mass and the points its joints and forces attach to (point data zero).
class VtkWriter {
 public:
  /// Creates `dir` and starts `dir/<prefix>.pvd`. @throws std::runtime_error.
  VtkWriter(const std::filesystem::path& dir, const System& sys, std::string prefix = "bodies",
            int subdivisions = 4);
  /// Writes `<prefix>_<k>.vtu` for the sample and rewrites the .pvd collection.
  void write(const OutputSample& sample);
  long filesWritten() const { return static_cast<long>(times_.size()); }

 private:
  void writeCollection() const;

  std::filesystem::path dir_;
  const System& sys_;
  std::string prefix_;
  int subdivisions_;
  std::vector<std::vector<Vec2>> rigidPoints_;  // per body: body-frame points of its line
  std::vector<double> times_;
};

}  // namespace flexmbd
