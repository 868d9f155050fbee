/// @file
/// The browser viewer (`flexmbd view`): one self-contained HTML page (three.js, the
/// viewer's script and the data compiled in) that animates drawings of a system
/// (viewer/system_drawing.hpp) with plots of results columns. It works offline from a file://
/// URL. The data's format is docs/viewer.md, "The page's data".
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "viewer/system_drawing.hpp"

namespace flexmbd {

/// One animation: the states drawn and their times (a run's output times, or the
/// fractions of a period of a mode shape).
struct ViewerClip {
  std::string name;
  std::string timeUnit = "s";  ///< "s", or "period" for a mode shape
  std::vector<double> times;
  std::vector<VecX> states;  ///< coordinates q (System order), one per time
};

/// A results column plotted under the animation, its cursor following the time.
struct ViewerPlotColumn {
  std::string name, unit;
  std::vector<double> values;  ///< one per plot time
};

struct ViewerPage {
  std::string title;
  std::string source;  ///< what the page shows (the run's folder), printed on it
  bool planar = true;
  Vec3 gravity = Vec3::Zero();
  std::vector<ViewerClip> clips;
  std::vector<double> plotTimes;  ///< the times of the plotted columns (clip 0's time axis)
  std::vector<ViewerPlotColumn> plots;
};

/// What was written.
struct ViewerPageInfo {
  std::uintmax_t bytes = 0;
  long frames = 0;  ///< over all clips
  int bodies = 0, points = 0, joints = 0;
};

/// Writes the page to `path`. Every clip is drawn by `drawer`; the drawings' topology must
/// be the same at every state (it is for one system).
/// @throws OutputWriteError if the file cannot be written; InputError for a page without
///         a frame.
ViewerPageInfo writeViewerPage(const std::filesystem::path& path, const SystemDrawer& drawer, const ViewerPage& page);

/// Base64 (RFC 4648, with padding) of the bytes.
std::string base64(const void* data, std::size_t bytes);

}  // namespace flexmbd
