#include "viewer/html_viewer.hpp"

#include <cmath>
#include <fstream>

#include <nlohmann/json.hpp>

#include "core/errors.hpp"
#include "simulation/simulation.hpp"
#include "viewer/viewer_assets.hpp"

namespace flexmbd {
namespace {

/// A quantity drawn as a colour map: its name on the page, unit, and value at a point.
struct Quantity {
  const char* name;
  const char* unit;
  double (*value)(const Drawing&, std::size_t point);
};

const Quantity kQuantities[] = {
    {"deflection", "m", [](const Drawing& d, std::size_t i) { return d.pointVectors[0].second[i].norm(); }},
    {"axial force", "N", [](const Drawing& d, std::size_t i) { return d.pointScalars[0].second[i]; }},
    {"bending moment", "N m", [](const Drawing& d, std::size_t i) { return d.pointScalars[1].second[i]; }},
    {"von Mises stress", "Pa", [](const Drawing& d, std::size_t i) { return d.pointScalars[2].second[i]; }},
};
constexpr int kNumQuantities = sizeof(kQuantities) / sizeof(kQuantities[0]);

/// A clip's arrays, Float32 as the page decodes them.
struct ClipArrays {
  std::vector<float> positions, displacements, joints, axes;
  std::vector<std::vector<float>> quantities = std::vector<std::vector<float>>(kNumQuantities);
};

void append(std::vector<float>& out, const std::vector<Vec3>& v) {
  for (const Vec3& p : v) {
    for (int k = 0; k < 3; ++k) out.push_back(static_cast<float>(p[k]));
  }
}

template <class T>
std::string base64Of(const std::vector<T>& v) {
  return base64(v.data(), v.size() * sizeof(T));
}

/// The topology every frame must share with the first.
bool sameTopology(const Drawing& a, const Drawing& b) {
  return a.points.size() == b.points.size() && a.cells == b.cells && a.jointNames.size() == b.jointNames.size();
}

/// JSON inside <script>: "</" would end the element early; "<\/" is the same JSON string.
std::string scriptSafe(std::string s) {
  for (std::size_t k = s.find("</"); k != std::string::npos; k = s.find("</", k + 3)) s.replace(k, 2, "<\\/");
  return s;
}

std::string htmlEscape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '&': out += "&amp;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

}  // namespace

std::string base64(const void* data, std::size_t bytes) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* p = static_cast<const unsigned char*>(data);
  std::string out;
  out.reserve(4 * ((bytes + 2) / 3));
  for (std::size_t i = 0; i < bytes; i += 3) {
    const unsigned v = (p[i] << 16) | (i + 1 < bytes ? p[i + 1] << 8 : 0) | (i + 2 < bytes ? p[i + 2] : 0);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += i + 1 < bytes ? kAlphabet[(v >> 6) & 63] : '=';
    out += i + 2 < bytes ? kAlphabet[v & 63] : '=';
  }
  return out;
}

ViewerPageInfo writeViewerPage(const std::filesystem::path& path, const SystemDrawer& drawer, const ViewerPage& page) {
  if (page.clips.empty() || page.clips.front().states.empty()) {
    throw InputError("view: nothing to draw (no output time in '" + page.source + "')");
  }
  const Drawing first = drawer.draw(page.clips.front().states.front());
  ViewerPageInfo info;
  info.bodies = static_cast<int>(first.bodyNames.size());
  info.points = static_cast<int>(first.points.size());
  info.joints = static_cast<int>(first.jointNames.size());

  // ----- stage 1: every clip's frames drawn, as Float32 arrays -----
  std::vector<ClipArrays> arrays(page.clips.size());
  std::vector<double> qMin(kNumQuantities, 0.0), qMax(kNumQuantities, 0.0);
  std::vector<bool> qUsed(kNumQuantities, false);
  for (std::size_t c = 0; c < page.clips.size(); ++c) {
    for (const VecX& q : page.clips[c].states) {
      const Drawing d = drawer.draw(q);
      if (!sameTopology(first, d)) throw std::logic_error("view: the drawing's topology changed between frames");
      append(arrays[c].positions, d.points);
      append(arrays[c].displacements, d.pointVectors[0].second);
      append(arrays[c].joints, d.jointPoints);
      append(arrays[c].axes, d.jointAxes);
      for (int k = 0; k < kNumQuantities; ++k) {
        for (std::size_t i = 0; i < d.points.size(); ++i) {
          const double v = kQuantities[k].value(d, i);
          arrays[c].quantities[k].push_back(static_cast<float>(v));
          qMin[k] = std::min(qMin[k], v);
          qMax[k] = std::max(qMax[k], v);
          if (v != 0.0) qUsed[k] = true;
        }
      }
      ++info.frames;
    }
  }

  // ----- stage 2: the page's data (docs/viewer.md, "The page's data") -----
  nlohmann::ordered_json j;
  j["format"] = "flexmbd-view 1";
  j["title"] = page.title;
  j["source"] = page.source;
  j["three"] = viewer_assets::threeVersion();
  j["planar"] = page.planar;
  j["gravity"] = {page.gravity.x(), page.gravity.y(), page.gravity.z()};
  j["bodies"] = first.bodyNames;
  j["points"] = first.points.size();
  j["cells"] = first.cells;
  std::vector<int> kinds;
  for (Drawing::CellKind k : first.cellKinds) kinds.push_back(k == Drawing::CellKind::Polygon ? 1 : 0);
  j["cell_kinds"] = kinds;
  j["cell_body"] = first.cellBody;
  j["joints"] = first.jointNames;
  nlohmann::ordered_json quantities = nlohmann::ordered_json::array();
  for (int k = 0; k < kNumQuantities; ++k) {
    if (qUsed[k]) quantities.push_back({{"name", kQuantities[k].name}, {"unit", kQuantities[k].unit},
                                        {"min", qMin[k]}, {"max", qMax[k]}});
  }
  j["quantities"] = quantities;
  nlohmann::ordered_json clips = nlohmann::ordered_json::array();
  for (std::size_t c = 0; c < page.clips.size(); ++c) {
    nlohmann::ordered_json cj;
    cj["name"] = page.clips[c].name;
    cj["time_unit"] = page.clips[c].timeUnit;
    cj["times"] = page.clips[c].times;
    cj["positions"] = base64Of(arrays[c].positions);
    // the elastic displacements (world axes), for the page's deformation scale; "" when
    // no body deforms
    cj["displacements"] = qUsed[0] ? base64Of(arrays[c].displacements) : "";
    cj["joint_positions"] = base64Of(arrays[c].joints);
    cj["joint_axes"] = base64Of(arrays[c].axes);
    nlohmann::ordered_json qs = nlohmann::ordered_json::array();
    for (int k = 0; k < kNumQuantities; ++k) {
      if (qUsed[k]) qs.push_back(base64Of(arrays[c].quantities[k]));
    }
    cj["quantities"] = qs;
    clips.push_back(cj);
  }
  j["clips"] = clips;
  nlohmann::ordered_json plots = nlohmann::ordered_json::array();
  for (const ViewerPlotColumn& p : page.plots) plots.push_back({{"name", p.name}, {"unit", p.unit}, {"values", p.values}});
  j["plot_times"] = page.plotTimes;
  j["plots"] = plots;

  // ----- stage 3: the page -----
  std::ofstream out(path, std::ios::binary);
  if (!out) throw OutputWriteError("view: cannot write '" + path.string() + "'");
  out << "<!doctype html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" << htmlEscape(page.title)
      << " - flexmbd view</title>\n<style>\n" << viewer_assets::viewerCss() << "</style>\n</head>\n<body>\n"
      << "<!-- three.js " << viewer_assets::threeVersion() << " (MIT licence, https://threejs.org), "
      << "loaded by the viewer's script from the element below -->\n"
      << "<script id=\"three-src\" type=\"text/plain\">" << viewer_assets::threeJs() << "</script>\n"
      << "<script id=\"flexmbd-data\" type=\"application/json\">"
      << scriptSafe(j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace)) << "</script>\n"
      << "<script type=\"module\">\n" << viewer_assets::viewerJs() << "</script>\n</body>\n</html>\n";
  out.close();
  if (!out) throw OutputWriteError("view: cannot write '" + path.string() + "' (disk full?)");
  info.bytes = std::filesystem::file_size(path);
  return info;
}

}  // namespace flexmbd
