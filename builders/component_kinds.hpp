/// @file
/// Every kind of component declared through the registry (core/component_kind.hpp):
/// the list the scene readers, the generated reference and the Python module take them from.
#pragma once

#include <string>
#include <vector>

#include "core/component_kind.hpp"

namespace flexmbd {

/// The declared kinds, in the order of their registration lines (builders/component_kinds.cpp).
const std::vector<ComponentKind>& componentKinds();

/// The kind of `section` with scene type `type`, or null.
const ComponentKind* findComponentKind(const std::string& section, const std::string& type);

}  // namespace flexmbd
