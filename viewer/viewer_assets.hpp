/// @file
/// The browser viewer's assets, compiled in (cmake/embed_viewer_assets.cmake): the page
/// `flexmbd view` writes works offline from a file:// URL, with nothing installed.
#pragma once

#include <string>

namespace flexmbd::viewer_assets {

/// three.js as the npm registry ships it (build/three.module.min.js; its licence, MIT,
/// is at its top).
const std::string& threeJs();
/// The viewer's own code (viewer/viewer.js, an ES module) and style (viewer/viewer.css).
const std::string& viewerJs();
const std::string& viewerCss();
/// The version of three.js compiled in, e.g. "0.160.1".
const char* threeVersion();

}  // namespace flexmbd::viewer_assets
