// How the engine sets up KLU for its DAE Jacobians (used by IdaSolver and by the
// micro-benchmarks, so both factor the same way).
#pragma once

#include <klu.h>

#include <cstdint>
#include <vector>

namespace flexmbd {

/// Constrained AMD ordering (elastic unknowns first; frame coordinates and multipliers
/// last, `groups` from DaeSystem::eliminationGroups()) and a pivot threshold that keeps
/// to it, for models with elastic coordinates; KLU's defaults otherwise. `groups` must
/// outlive every klu_l_analyze with `common`.
void configureKluOrdering(klu_l_common& common, const std::vector<int64_t>& groups);

}  // namespace flexmbd
