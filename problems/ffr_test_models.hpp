// Small builders of flexible-body models shared by the FFR validation tests.
#pragma once

#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "bodies/ffr_body_2d.hpp"
#include "scene/scene.hpp"

namespace flexmbd::testmodels {

/// The elastic slider-crank scene of examples/slider_crank_elastic.json with changes.
inline nlohmann::json elasticSliderCrankJson() {
  std::ifstream in(std::string(FLEXMBD_SOURCE_DIR) + "/examples/slider_crank_elastic.json");
  std::stringstream ss;
  ss << in.rdbuf();
  return nlohmann::json::parse(ss.str());
}

/// The spatial elastic slider crank of examples/spatial_slider_crank_elastic.json with
/// `elements` rod elements (and `modes` modes if > 0): the scaling benchmark and its tests.
inline nlohmann::json spatialElasticCrankJson(int elements, int modes = 0) {
  std::ifstream in(std::string(FLEXMBD_SOURCE_DIR) + "/examples/spatial_slider_crank_elastic.json");
  nlohmann::json j = nlohmann::json::parse(in);
  for (auto& b : j["bodies"]) {
    if (b["name"] != "rod") continue;
    b["beam"]["elements"] = elements;
    if (modes > 0) b["modes"] = modes;
  }
  return j;
}

/// A planar pendulum chain of `links` steel links (0.3 m, 8 x 8 mm, 4 beam elements each
/// reduced to `modes` normal modes under pinned-pinned reference conditions) on revolute
/// joints, the first to the ground at the origin, released horizontal under gravity;
/// no solver keys (its equations are banded, its cost can be linear in links).
inline nlohmann::json flexibleChainJson(int links, int modes = 4) {
  using json = nlohmann::json;
  constexpr double kLinkLength = 0.3;
  json bodies = json::array(), joints = json::array();
  for (int k = 0; k < links; ++k) {
    const std::string name = "link" + std::to_string(k + 1);
    bodies.push_back({{"name", name},
                      {"type", "flexible"},
                      {"position", {kLinkLength * k, 0.0}},
                      {"section", {{"width", 0.008}, {"height", 0.008}, {"youngs_modulus", 2e11}, {"density", 7870}}},
                      {"beam", {{"length", kLinkLength}, {"elements", 4}}},
                      {"reference", {{"type", "pinned_pinned"}}},
                      {"modes", modes}});
    joints.push_back({{"name", "J" + std::to_string(k + 1)},
                      {"type", "revolute"},
                      {"bodies", {k == 0 ? std::string("ground") : "link" + std::to_string(k), name}},
                      {"points", {{k == 0 ? 0.0 : kLinkLength, 0.0}, {0.0, 0.0}}}});
  }
  return {{"name", "flexible pendulum chain"}, {"gravity", {0.0, -9.81}}, {"bodies", bodies}, {"joints", joints}};
}

/// Elastic slider-crank with N elements, Young's modulus scaled by eScale, `modes`
/// modes (0: nodal), `revolutions` crank turns at rtol/atol.
inline Scene elasticSliderCrank(int N, double eScale, int modes, double revolutions, double rtol, double atol,
                                double rayleighBeta = 0.0) {
  nlohmann::json j = elasticSliderCrankJson();
  auto& rod = j["bodies"][1];
  rod["beam"]["elements"] = N;
  rod["section"]["youngs_modulus"] = 2e11 * eScale;
  if (modes > 0) rod["modes"] = modes;
  if (rayleighBeta > 0) rod["section"]["damping"] = rayleighBeta;
  j["solver"]["rtol"] = rtol;
  j["solver"]["atol"] = atol;
  j["solver"]["t_end"] = revolutions * 2 * M_PI / 150.0;
  Scene s = parseScene(j);
  s.solver.progress = false;
  return s;
}

}  // namespace flexmbd::testmodels
