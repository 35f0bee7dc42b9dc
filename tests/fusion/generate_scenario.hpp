// A gvins-sim dataset from a scenario given as YAML text (the replay tests' datasets): parsed as
// `name`.yaml, generated into `dir` with `seed` on two threads.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "gvins/sim/dataset_generator.hpp"
#include "gvins/sim/scenario.hpp"

namespace gvins::fusion::test {

inline sim::GenerationSummary generateScenario(const std::filesystem::path& dir, const std::string& yaml,
                                               const std::string& name, std::uint64_t seed) {
  const sim::Scenario sc = sim::parseScenario(yaml, name + ".yaml");
  sim::GenerationOptions opt;
  opt.seed = seed;
  opt.threads = 2;
  return sim::generateDataset(sc, dir, opt);
}

}  // namespace gvins::fusion::test
