// Every key the scene readers accept is documented in docs/scene-format.md, and every
// key documented there is accepted. The readers take their allowed keys
// from scene/scene_keys.hpp; the docs tag each key table with the objects it documents
// (`<!-- keys: body.rigid body.flexible -->` above the table, one key per row in the
// first column). Both are compared object by object.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "scene/scene_keys.hpp"

namespace {

using KeySets = std::map<std::string, std::set<std::string>>;

std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

/// The documented keys per object: the first cell of every row of a table tagged
/// `<!-- keys: ID ... -->` (the tag on the line before the table, or a few lines above
/// it with only blank lines between), the key in backquotes.
KeySets documentedKeys(const std::string& markdown) {
  KeySets out;
  std::istringstream in(markdown);
  const std::regex tag(R"(^<!--\s*keys:\s*(.*?)\s*-->\s*$)");
  const std::regex keyCell(R"(^\|\s*`([^`]+)`\s*\|)");
  std::vector<std::string> ids;
  bool inTable = false;
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (std::regex_match(line, m, tag)) {
      ids.clear();
      std::istringstream idList(m[1].str());
      for (std::string id; idList >> id;) {
        ids.push_back(id);
        out[id];  // an object whose table is empty still counts as documented
      }
      inTable = false;
      continue;
    }
    if (!line.empty() && line[0] == '|') {
      if (ids.empty()) continue;  // a table that lists no keys (types, columns, ...)
      inTable = true;
      if (std::regex_search(line, m, keyCell)) {
        for (const auto& id : ids) out[id].insert(m[1].str());
      }
      continue;
    }
    if (inTable || !line.empty()) {  // the table (or the text after a tag) ended
      ids.clear();
      inTable = false;
    }
  }
  return out;
}

KeySets acceptedKeys() {
  KeySets out;
  for (const auto& [id, keys] : flexmbd::scenekeys::allObjects()) out[id].insert(keys->begin(), keys->end());
  return out;
}

/// One message per disagreement; empty if docs and readers agree.
std::vector<std::string> compare(const KeySets& documented, const KeySets& accepted) {
  std::vector<std::string> problems;
  for (const auto& [id, keys] : accepted) {
    const auto d = documented.find(id);
    if (d == documented.end()) {
      problems.push_back("object " + id + " has no key table in the docs");
      continue;
    }
    for (const auto& k : keys) {
      if (!d->second.count(k)) problems.push_back(id + ": key \"" + k + "\" is accepted but not documented");
    }
    for (const auto& k : d->second) {
      if (!keys.count(k)) problems.push_back(id + ": key \"" + k + "\" is documented but no reader accepts it");
    }
  }
  for (const auto& [id, keys] : documented) {
    if (!accepted.count(id)) problems.push_back("the docs tag a table with " + id + ", which no reader knows");
  }
  return problems;
}

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += x + "\n";
  return s;
}

const std::string kDoc = FLEXMBD_SCENE_FORMAT_DOC;

}  // namespace

TEST(DocsKeys, EveryAcceptedKeyIsDocumentedAndEveryDocumentedKeyIsAccepted) {
  const std::string text = readText(kDoc);
  ASSERT_FALSE(text.empty()) << "cannot read " << kDoc;
  const KeySets documented = documentedKeys(text);
  const auto problems = compare(documented, acceptedKeys());
  EXPECT_TRUE(problems.empty()) << kDoc << ":\n" << joined(problems);
  // Each family of objects is covered (a lost tag would hide a whole format).
  for (const char* id : {"scene", "body.rigid", "body.flexible", "body.flexible_invariants", "joint.prismatic",
                         "driver.joint_angle", "law.harmonic", "force.applied_load", "output.deflection", "solver",
                         "kinematics", "kinematics.analysis", "tensegrity", "tensegrity.solver.massless_cables"}) {
    EXPECT_TRUE(documented.count(id)) << id;
  }
}

TEST(DocsKeys, TheComparisonCatchesAKeyMissingFromTheDocsAndAKeyNoReaderAccepts) {
  const std::string text = readText(kDoc);
  ASSERT_FALSE(text.empty());
  // A key accepted by a reader whose docs row is gone.
  std::string missing = text;
  const std::string row = "| `geometric_stiffening` |";
  const auto at = missing.find(row);
  ASSERT_NE(at, std::string::npos);
  missing.erase(at, missing.find('\n', at) + 1 - at);
  auto problems = compare(documentedKeys(missing), acceptedKeys());
  ASSERT_EQ(problems.size(), 1u) << joined(problems);
  EXPECT_NE(problems[0].find("body.flexible: key \"geometric_stiffening\" is accepted but not documented"),
            std::string::npos)
      << problems[0];
  // A documented key no reader accepts.
  std::string extra = text;
  const auto solverRow = extra.find("| `rtol`          |");
  ASSERT_NE(solverRow, std::string::npos);
  extra.insert(solverRow, "| `rtoll` | number | 1 | - | a typo |\n");
  problems = compare(documentedKeys(extra), acceptedKeys());
  ASSERT_EQ(problems.size(), 1u) << joined(problems);
  EXPECT_NE(problems[0].find("solver: key \"rtoll\" is documented but no reader accepts it"), std::string::npos)
      << problems[0];
}

TEST(DocsKeys, ReadersTakeTheirAllowedKeysFromTheTable) {
  // A literal list passed to allowOnly would bypass scene/scene_keys.hpp (and this test).
  for (const char* file : {"scene/scene.cpp", "scene/json_reader.cpp", "linkage/kinematics_scene.cpp",
                           "tensegrity/tensegrity_scene.cpp"}) {
    const std::string src = readText(std::string(FLEXMBD_SOURCE_DIR) + "/" + file);
    ASSERT_FALSE(src.empty()) << file;
    EXPECT_EQ(src.find("allowOnly({"), std::string::npos) << file << " passes a literal key list to allowOnly";
    EXPECT_NE(src.find("scenekeys::"), std::string::npos) << file;
  }
}
