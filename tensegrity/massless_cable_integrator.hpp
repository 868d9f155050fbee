/// @file
/// Method 2 of Doc001 (Tamba & Kanno): massless elastic cables. A cable
/// that snaps taut receives no impulse (v+ = v- when its mass m_c -> 0), so the motion
/// follows the smooth equations with the piecewise (tension-only) cable law
///   M u'' = f(t) - g_struts(u) - sum_c b_c(u) tau_c(u),  tau_c = (EA/l0) max(l_c - l0, 0),
/// integrated as a first-order ODE y = [u_free, v_free] with CVODE. The switch functions
/// (l_c - l0)/l0 are CVODE root functions, so every slack/taut switch is located to the
/// solver's tolerance; the integration restarts at each switch (the force is only C0
/// there).
#pragma once

#include "integrators/cvode_solver.hpp"
#include "tensegrity/tensegrity_output.hpp"
#include "tensegrity/tensegrity_structure.hpp"

namespace flexmbd {

struct MasslessCableSettings {
  double tStart = 0.0;
  double tEnd = 1.0;
  double outputStep = 0.01;  ///< > 0
  CvodeOptions cvode;
  double slackTolerance = 1e-9;  ///< slack flag of the samples: l < l0 (1 - tol)
  bool detectContacts = false;   ///< checked between consecutive output times and switches
};

class MasslessCableIntegrator {
 public:
  /// @pre structure finalized and outliving the integrator.
  /// @throws InputError if a cable is inextensible (method 2 needs EA) or on bad settings.
  MasslessCableIntegrator(const TensegrityStructure& structure, const MasslessCableSettings& settings);

  /// Never throws on solver failure: the summary says ok = false with CVODE's reason.
  TensegrityRunSummary run(const TensegrityObserver& observer) const;

 private:
  const TensegrityStructure& s_;
  MasslessCableSettings settings_;
};

}  // namespace flexmbd
