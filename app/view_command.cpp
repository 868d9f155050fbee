#include "app/view_command.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>

#include <nlohmann/json.hpp>

#include "app/command_line.hpp"
#include "bodies/ffr_body_3d.hpp"
#include "bodies/rigid_body_3d.hpp"
#include "core/errors.hpp"
#include "viewer/html_viewer.hpp"
#include "results/results_table.hpp"
#include "scene/scene.hpp"

namespace flexmbd {
namespace {

namespace fs = std::filesystem;

using cli::kExitOk;
using cli::kExitFailure;
using cli::kExitInputError;
/// Frames drawn at most by default: a page of a few MB that opens in seconds.
constexpr long kDefaultMaxFrames = 1000;
/// Columns plotted by default at most.
constexpr std::size_t kDefaultPlots = 4;

struct ViewOptions {
  fs::path dir, out, scene;
  std::vector<std::string> columns;
  long maxFrames = kDefaultMaxFrames;
};

ViewOptions parseOptions(const std::vector<std::string>& args) {
  const cli::SplitArguments a = cli::splitArguments(args, {"--out", "--scene", "--columns", "--max-frames"}, {}, "view: ");
  if (a.positional.size() != 1) {
    throw cli::UsageError("view expects one folder (flexmbd view DIR [--out FILE.html]), got " +
                          std::to_string(a.positional.size()));
  }
  ViewOptions o;
  o.dir = a.positional[0];
  o.out = a.values.count("--out") ? fs::path(a.values.at("--out")) : o.dir / "view.html";
  if (a.values.count("--scene")) o.scene = a.values.at("--scene");
  if (a.values.count("--columns")) {
    std::string c = a.values.at("--columns");
    for (std::size_t k = 0; k <= c.size();) {
      const std::size_t e = std::min(c.find(',', k), c.size());
      if (e > k) o.columns.push_back(c.substr(k, e - k));
      k = e + 1;
    }
    if (o.columns.empty()) throw cli::UsageError("view: --columns names no column");
  }
  if (a.values.count("--max-frames")) {
    const double n = cli::parseNumberOption("--max-frames", a.values.at("--max-frames"));
    if (!(n >= 2) || n != std::floor(n) || n > 1e6) {
      throw cli::UsageError("view: --max-frames must be a whole number from 2 to 1000000, got " +
                            a.values.at("--max-frames"));
    }
    o.maxFrames = static_cast<long>(n);
  }
  return o;
}

nlohmann::json readJson(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError("cannot read '" + path.string() + "'");
  try {
    return nlohmann::json::parse(in);
  } catch (const std::exception& e) {
    throw InputError("'" + path.string() + "' is not valid JSON: " + e.what());
  }
}

/// The scene of the run: --scene, else the "scene_file" its summary (or modes.json) recorded.
fs::path sceneOf(const ViewOptions& o, const fs::path& record) {
  if (!o.scene.empty()) return o.scene;
  const nlohmann::json j = readJson(record);
  if (!j.contains("scene_file") || !j["scene_file"].is_string()) {
    throw InputError("'" + record.string() + "' does not name its scene file (runs of earlier versions record none): "
                     "give it with --scene SCENE.json");
  }
  const fs::path scene = j["scene_file"].get<std::string>();
  if (!fs::exists(scene)) {
    throw InputError("the scene '" + scene.string() + "' recorded in '" + record.string() +
                     "' no longer exists: give it with --scene SCENE.json");
  }
  return scene;
}

bool isSpatial(const System& sys) {
  for (int b = 1; b < sys.numBodies(); ++b) {
    const Body& body = sys.body(BodyIndex(b));
    if (dynamic_cast<const RigidBody3d*>(&body) || dynamic_cast<const FfrBody3d*>(&body)) return true;
  }
  return false;
}

/// The columns of the coordinates q in the results, in System order.
/// @throws InputError naming the first coordinate missing (the scene changed since the run).
std::vector<int> coordinateColumns(const System& sys, const ResultsTable& t, const fs::path& scene,
                                   const fs::path& dir) {
  std::vector<int> cols;
  for (const std::string& name : sys.coordinateNames()) {
    const int c = t.column(name);
    if (c < 0) {
      throw InputError("the results in '" + dir.string() + "' have no column '" + name + "' of the scene '" +
                       scene.string() + "': the scene is not the one that ran (changed since?); give the right one "
                       "with --scene");
    }
    cols.push_back(c);
  }
  return cols;
}

/// The unit of a results column: from the run's summary.json "units" (driver efforts),
/// else from its last part ("rod.x" -> "m"); "" if unknown.
std::string unitOf(const std::string& column, const nlohmann::json& units = {}) {
  if (units.is_object() && units.contains(column) && units[column].is_string()) return units[column];
  static const std::map<std::string, std::string> kUnits = {
      {"x", "m"}, {"y", "m"}, {"z", "m"}, {"ux", "m"}, {"uy", "m"}, {"uz", "m"}, {"theta", "rad"},
      {"x_dot", "m/s"}, {"y_dot", "m/s"}, {"z_dot", "m/s"}, {"theta_dot", "rad/s"}, {"wx", "rad/s"},
      {"wy", "rad/s"}, {"wz", "rad/s"}, {"N", "N"}, {"Qy", "N"}, {"Qz", "N"}, {"M", "N m"}, {"Mx", "N m"},
      {"My", "N m"}, {"Mz", "N m"}, {"fx", "N"}, {"fy", "N"}, {"fz", "N"}, {"mz", "N m"}, {"angle", "rad"},
      {"displacement", "m"}, {"angle_dot", "rad/s"}, {"vx", "m/s"}, {"vy", "m/s"}, {"vz", "m/s"},
      {"von_mises", "Pa"}, {"energy", "J"}, {"kinetic", "J"}, {"potential", "J"}, {"t", "s"}};
  const std::size_t dot = column.rfind('.');
  const auto it = kUnits.find(dot == std::string::npos ? column : column.substr(dot + 1));
  return it == kUnits.end() ? "" : it->second;
}

/// The plotted columns: --columns, else the scene's outputs (deflections, points), else
/// the first bodies' positions.
std::vector<std::string> plotColumns(const ViewOptions& o, const Scene& scene, const ResultsTable& t) {
  if (!o.columns.empty()) {
    for (const std::string& c : o.columns) {
      if (t.column(c) < 0) {
        throw InputError("view: --columns: no column '" + c + "' in the results of '" + o.dir.string() +
                         "' (flexmbd plot --help lists how columns are named; the header of results.csv has them all)");
      }
    }
    return o.columns;
  }
  std::vector<std::string> out;
  for (const OutputRequest& r : scene.outputs) {
    for (const std::string& c : r.columnNames()) {
      if (out.size() < kDefaultPlots && !unitOf(c).empty() && t.column(c) >= 0) out.push_back(c);
    }
  }
  const bool spatial = isSpatial(scene.system);
  for (const std::string& c : scene.system.coordinateNames()) {
    if (out.size() >= kDefaultPlots) break;
    const std::string last = c.substr(c.rfind('.') + 1);
    if (last == "x" || last == "y" || (spatial ? last == "z" : last == "theta")) out.push_back(c);
  }
  return out;
}

/// The rows drawn: all, or maxFrames of them evenly spread, the first and last included.
std::vector<std::size_t> frameRows(std::size_t rows, long maxFrames) {
  std::vector<std::size_t> r;
  const std::size_t n = std::min<std::size_t>(rows, static_cast<std::size_t>(maxFrames));
  for (std::size_t k = 0; k < n; ++k) r.push_back(n == 1 ? 0 : (k * (rows - 1) + (n - 1) / 2) / (n - 1));
  return r;
}

ViewerPage runPage(const ViewOptions& o, const Scene& scene, const fs::path& scenePath) {
  const ResultsTable t = readResults(o.dir);
  if (t.rows.empty()) throw InputError("the results in '" + o.dir.string() + "' have no row: nothing to draw");
  const std::vector<int> cols = coordinateColumns(scene.system, t, scenePath, o.dir);
  ViewerPage page;
  page.title = scene.name.empty() ? scenePath.filename().string() : scene.name;
  page.source = o.dir.string();
  page.planar = !isSpatial(scene.system);
  page.gravity = scene.system.gravity();
  ViewerClip clip;
  clip.name = "run";
  const int tc = t.column("t");
  for (std::size_t r : frameRows(t.rows.size(), o.maxFrames)) {
    VecX q(cols.size());
    for (std::size_t k = 0; k < cols.size(); ++k) q[static_cast<Eigen::Index>(k)] = t.rows[r][cols[k]];
    clip.times.push_back(tc >= 0 ? t.rows[r][tc] : static_cast<double>(r));
    clip.states.push_back(std::move(q));
  }
  page.clips.push_back(std::move(clip));
  for (const auto& row : t.rows) page.plotTimes.push_back(tc >= 0 ? row[tc] : 0.0);
  nlohmann::json units;
  try {
    units = readJson(o.dir / "summary.json").value("units", nlohmann::json::object());
  } catch (const InputError&) {  // read before; a summary without units: names tell
  }
  for (const std::string& c : plotColumns(o, scene, t)) {
    ViewerPlotColumn p{c, unitOf(c, units), {}};
    const int k = t.column(c);
    for (const auto& row : t.rows) p.values.push_back(row[k]);
    page.plots.push_back(std::move(p));
  }
  return page;
}

/// A `flexmbd modes` folder: one clip per mode from mode_states.csv (a period of each shape).
ViewerPage modesPage(const ViewOptions& o, const Scene& scene, const fs::path& scenePath) {
  // mode_states.csv: mode, phase, then the coordinates
  const ResultsTable states = readCsvTable(o.dir / "mode_states.csv");
  const std::vector<int> cols = coordinateColumns(scene.system, states, scenePath, o.dir);
  const int mc = states.column("mode"), pc = states.column("phase");
  if (mc < 0 || pc < 0) throw InputError("'" + (o.dir / "mode_states.csv").string() + "' has no mode and phase columns");
  std::vector<double> hz;
  try {
    const ResultsTable modes = readCsvTable(o.dir / "modes.csv");
    const int fc = modes.column("frequency_hz");
    for (const auto& row : modes.rows) hz.push_back(fc >= 0 ? row[fc] : std::nan(""));
  } catch (const InputError&) {
  }
  ViewerPage page;
  page.title = (scene.name.empty() ? scenePath.filename().string() : scene.name) + ": mode shapes";
  page.source = o.dir.string();
  page.planar = !isSpatial(scene.system);
  page.gravity = scene.system.gravity();
  for (const auto& row : states.rows) {
    const int m = static_cast<int>(row[mc]);
    if (page.clips.empty() || page.clips.back().name.rfind("mode " + std::to_string(m) + ":", 0) != 0) {
      ViewerClip c;
      char name[96];
      const double f = m >= 1 && m <= static_cast<int>(hz.size()) ? hz[m - 1] : std::nan("");
      std::snprintf(name, sizeof name, "mode %d: %.6g Hz", m, f);
      c.name = name;
      c.timeUnit = "period";
      page.clips.push_back(std::move(c));
    }
    VecX q(cols.size());
    for (std::size_t k = 0; k < cols.size(); ++k) q[static_cast<Eigen::Index>(k)] = row[cols[k]];
    page.clips.back().times.push_back(row[pc]);
    page.clips.back().states.push_back(std::move(q));
  }
  return page;
}

}  // namespace

int runViewCommand(const std::vector<std::string>& args) {
  ViewOptions o;
  ViewerPage page;
  std::optional<Scene> scene;
  fs::path scenePath;
  try {
    o = parseOptions(args);
    std::error_code ec;
    if (!fs::is_directory(o.dir, ec)) throw InputError("'" + o.dir.string() + "' is not a folder (the --out of a run)");
    const bool modes = fs::exists(o.dir / "modes.json", ec);
    if (!modes && !fs::exists(o.dir / "summary.json", ec)) {
      throw InputError("'" + o.dir.string() + "' has no summary.json or modes.json: not the folder of flexmbd run or "
                       "flexmbd modes");
    }
    scenePath = sceneOf(o, o.dir / (modes ? "modes.json" : "summary.json"));
    scene.emplace(loadScene(scenePath.string()));
    page = modes ? modesPage(o, *scene, scenePath) : runPage(o, *scene, scenePath);
  } catch (const std::exception& e) {
    cli::printError(e.what());
    return kExitInputError;
  }
  try {
    const SystemDrawer drawer(scene->system, 4, scene->geometry, scene->feBodies, /*inertiaBoxes=*/true);
    const ViewerPageInfo info = writeViewerPage(o.out, drawer, page);
    std::error_code ec;
    const fs::path absolute = fs::absolute(o.out, ec);
    std::printf("flexmbd: view: %s (%.1f MB): %ld frames of %d bodies and %d joints, %zu plots; open "
                "file://%s in a browser\n",
                o.out.string().c_str(), static_cast<double>(info.bytes) / 1e6, info.frames, info.bodies, info.joints,
                page.plots.size(), absolute.lexically_normal().string().c_str());
    return kExitOk;
  } catch (const InputError& e) {
    cli::printError(e.what());
    return kExitInputError;
  } catch (const std::exception& e) {
    cli::printError(e.what());
    return kExitFailure;
  }
}

}  // namespace flexmbd
