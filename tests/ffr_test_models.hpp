// Small builders of flexible-body models shared by the FFR validation tests.
#pragma once

#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "bodies/ffr_body_2d.hpp"
#include "io/scene.hpp"

namespace flexmbd::testmodels {

/// The elastic slider-crank scene of examples/slider_crank_elastic.json with changes.
inline nlohmann::json elasticSliderCrankJson() {
  std::ifstream in(std::string(FLEXMBD_SOURCE_DIR) + "/examples/slider_crank_elastic.json");
  std::stringstream ss;
  ss << in.rdbuf();
  return nlohmann::json::parse(ss.str());
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
