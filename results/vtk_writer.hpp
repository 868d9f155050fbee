/// @file
/// VTK output for ParaView: one .vtu (unstructured grid, ASCII XML) per output time and
/// a .pvd collection, written as the run goes (a failed run keeps what was written).
/// Every .vtu names what it draws: a FieldData string array "body_names" (one entry per
/// body drawn, in the order of the CellData "body_index" of its cells; ParaView shows it
/// in the Information panel and the spreadsheet view), repeated in an XML comment.
#pragma once

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "bodies/body_geometry.hpp"
#include "viewer/system_drawing.hpp"
#include "core/system.hpp"
#include "simulation/simulation.hpp"
#include "tensegrity/tensegrity_output.hpp"

namespace flexmbd {

class TensegrityStructure;

/// The frames of one run: `<prefix>_NNNNNN.vtu` per output and `<prefix>.pvd`.
class VtkCollection {
 public:
  /// Creates `dir`. @throws std::runtime_error.
  VtkCollection(const std::filesystem::path& dir, std::string prefix);
  /// The path of the next frame.
  std::filesystem::path nextFrame() const;
  /// Records the frame written at time t and rewrites the .pvd collection.
  void add(double t);
  long frames() const { return static_cast<long>(times_.size()); }

 private:
  std::filesystem::path dir_;
  std::string prefix_;
  std::vector<double> times_;
};

/// Every body as poly-lines: a flexible beam body as its deformed axis (each element
/// drawn with `subdivisions` segments, point data: elastic displacement, axial force N,
/// bending moment M); a rigid body as the line through its frame origin, its centre of
/// mass and the points its joints and forces attach to (point data zero); a
/// flexible_invariants body as the line through its attachment points (the "points" of
/// its invariants, in their order; point data: their elastic displacement). Cell data
/// "body_index" and field data "body_names" name the body of every cell.
class VtkWriter {
 public:
  /// Creates `dir` and starts `dir/<prefix>.pvd`. @throws std::runtime_error.
  /// `geometry`: shapes drawn as surfaces (polygons) on rigid bodies (Scene::geometry).
  /// `feBodies`: the fe_bodies drawn as their deformed outer surface (Scene::feBodies),
  /// with point data "von_mises" where they have stress shapes (0 elsewhere).
  VtkWriter(const std::filesystem::path& dir, const System& sys, std::string prefix = "bodies",
            int subdivisions = 4, const std::vector<BodyGeometry>& geometry = {},
            const std::vector<FeBodyDrawing>& feBodies = {});
  /// Writes `<prefix>_<k>.vtu` for the sample and rewrites the .pvd collection.
  void write(const OutputSample& sample);
  long filesWritten() const { return collection_.frames(); }
  /// Bodies with nothing to draw (a flexible_invariants body without attachment
  /// points): they are missing from every frame, and the command says so on stderr.
  const std::vector<std::string>& bodiesNotDrawn() const { return drawer_.bodiesNotDrawn(); }

 private:
  VtkCollection collection_;
  SystemDrawer drawer_;
};

/// A tensegrity structure: its nodes as points (point data: velocity) and every member
/// as a line cell (cell data: "axial_force", the strut force N = EA (l - l0)/l0 (Doc001) or the
/// cable tension of the sample; "member_type" 0 strut, 1 cable; "slack" 0/1 for cables).
/// Field data "body_names" holds the structure's name (the scene name, or
/// "tensegrity"), "member_names" the member of every cell.
class TensegrityVtkWriter {
 public:
  TensegrityVtkWriter(const std::filesystem::path& dir, const TensegrityStructure& s, std::string name,
                      std::string prefix = "bodies");
  void write(const TensegritySample& sample);
  long filesWritten() const { return collection_.frames(); }

 private:
  VtkCollection collection_;
  const TensegrityStructure& s_;
  std::string name_;
};

}  // namespace flexmbd
