// Issue 11 ("Crashes, silent wrong results, lost data"): each defect found by fuzzing and
// by trying the engine as a new user, reproduced through the command line. Every test
// here failed before its fix.
#include <gtest/gtest.h>

#include <csignal>
#include <string>

#include "cli_fixture.hpp"

namespace fs = std::filesystem;

namespace {

const std::string kSourceDir = FLEXMBD_SOURCE_DIR;

nlohmann::json exampleScene(const std::string& name) {
  return nlohmann::json::parse(readFile(kSourceDir + "/examples/" + name));
}

class Hardening : public Cli {
 protected:
  CliResult runScene(const std::string& command, const fs::path& scene, const fs::path& out,
                     const std::string& extra = "") const {
    return run(command + " " + shellQuote(scene.string()) + " --out " + shellQuote(out.string()) +
               (command == "run" ? " --quiet" : "") +
               (extra.empty() ? "" : " " + extra));
  }
  fs::path writeText(const std::string& name, const std::string& text) const {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }
};

// Longest error line accepted from a scene with a 100,000-character name or value: the
// message quotes shortened values (60 characters) and is cut at 1,000 characters.
constexpr std::size_t kMaxErrorLine = 1100;

// ----- item 1: deep nesting, huge values in messages ---------------------------------

TEST_F(Hardening, DeeplyNestedJsonIsAnInputErrorForEverySubcommand) {
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  const std::string deepName = "{\"name\": " + deep + "}";
  const std::string deepTensegrity = "{\"model\": \"tensegrity\", \"nodes\": " + deep + "}";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"run", deep}, {"run", deepName}, {"run", deepTensegrity}, {"kinematics", deep}, {"kinematics", deepName}};
  int k = 0;
  for (const auto& [command, text] : cases) {
    const fs::path scene = writeText("deep" + std::to_string(k++) + ".json", text);
    const CliResult r = runScene(command, scene, dir_ / "out");
    EXPECT_EQ(r.status, 2) << command << " " << text.substr(0, 40) << ": " << r.err;
    EXPECT_TRUE(IsOneErrorLine(r.err));
    EXPECT_NE(r.err.find("nested more than 64 levels"), std::string::npos) << r.err;
  }
}

TEST_F(Hardening, HugeNamesAndValuesAreShortenedInErrors) {
  const std::string longName(100000, 'n');
  nlohmann::json j = example();
  j["bodies"][1]["name"] = longName;
  j["bodies"][1]["masss"] = 1.0;  // an unknown key in the body with the long name
  CliResult r = runScene("run", writeScene("long_name.json", j), dir_ / "out");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_NE(r.err.find("masss"), std::string::npos) << r.err.substr(0, 300);
  EXPECT_LT(r.err.size(), kMaxErrorLine);

  j = example();
  j["name"] = nlohmann::json::array({std::string(100000, 'x'), std::string(100000, 'y')});
  r = runScene("run", writeScene("long_value.json", j), dir_ / "out");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_NE(r.err.find("\"name\""), std::string::npos) << r.err.substr(0, 300);
  EXPECT_LT(r.err.size(), kMaxErrorLine);

  j = example();
  j["joints"][0]["bodies"][0] = longName;  // a reference to an unknown body
  r = runScene("run", writeScene("long_ref.json", j), dir_ / "out");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(IsOneErrorLine(r.err));
  EXPECT_NE(r.err.find("unknown body"), std::string::npos) << r.err.substr(0, 300);
  EXPECT_LT(r.err.size(), kMaxErrorLine);
}

}  // namespace
