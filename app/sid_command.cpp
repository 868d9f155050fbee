#include "app/sid_command.hpp"

#include <iostream>

#include "app/command_line.hpp"
#include "bodies/ffr_beam_model_3d.hpp"
#include "bodies/ffr_body_3d.hpp"
#include "bodies/sid_data.hpp"
#include "core/errors.hpp"
#include "core/number_text.hpp"
#include "scene/scene.hpp"
#include "fe_import/sid_file.hpp"

namespace flexmbd {

namespace {

using cli::kExitOk;
using cli::kExitInputError;

/// The spatial flexible body `name` of the scene.
/// @throws InputError naming the body: none of that name, or not a spatial flexible body.
const FfrBody3d& flexibleBody(const Scene& scene, const std::string& name, const std::string& scenePath) {
  const BodyIndex i = scene.system.findBody(name);  // throws naming the body and the bodies there are
  const auto* b = dynamic_cast<const FfrBody3d*>(&scene.system.body(i));
  if (!b) {
    throw InputError(scenePath + ": body '" + name + "' is not a spatial flexible body (\"flexible\", " +
                     "\"flexible_invariants\", \"fe_body\" or \"sid_body\" in a \"dimension\": 3 scene); " +
                     "only those have a SID");
  }
  return *b;
}

}  // namespace

int runSidCommand(const std::vector<std::string>& args) {
  try {
    const cli::SplitArguments a = cli::splitArguments(args, {"--body", "--out"}, {}, "sid: ");
    if (a.positional.size() != 1) {
      throw cli::UsageError("sid expects one scene file (flexmbd sid SCENE.json --body NAME --out FILE), got " +
                            std::to_string(a.positional.size()));
    }
    for (const char* required : {"--body", "--out"}) {
      if (!a.values.count(required)) throw cli::UsageError(std::string("sid needs the option ") + required);
    }
    const std::string& scenePath = a.positional[0];
    const Scene scene = loadScene(scenePath);
    const FfrBody3d& body = flexibleBody(scene, a.values.at("--body"), scenePath);
    const std::string& out = a.values.at("--out");
    FfrInvariants3d inv = body.invariants();
    const bool stiffening = body.model() && body.model()->geometricStiffening();
    if (stiffening) inv.spinStiffness = linearSpinStiffness(*body.model());
    writeSidFile(sidFromInvariants(inv), out);
    std::cout << "flexmbd: sid: body '" << body.name() << "': " << body.invariants().points.size() << " nodes, "
              << body.numElastic() << " elastic coordinates, mass " << fmt(body.mass(), 6) << " kg; wrote "
              << out << std::endl;
    if (stiffening) {
      std::cout << "flexmbd: sid: note: the beam's geometric stiffening is written as its spin stiffness (Oe's "
                   "first-order term), linearised about the undeformed beam; stiffening by other loads is not in "
                   "the SID"
                << std::endl;
    }
    return kExitOk;
  } catch (const std::exception& e) {
    cli::printError(e.what());
    return kExitInputError;
  }
}

}  // namespace flexmbd
