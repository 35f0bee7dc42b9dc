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

/// The mono take-off flight of the initialisation tests: a 20 m lawnmower with take-off (2 s on
/// the ground, climb at 3 m/s), cam0 only looking down, feature tracks at 20 Hz; `tail` adds the
/// remaining keys (lever arm, gnss).
inline std::string monoTakeoffScenario(const std::string& name, const std::string& tail) {
  return "name: " + name +
         "\n"
         "origin: {latitude_deg: 35.134707705, longitude_deg: 136.977577939, height_m: 104.853}\n"
         "start_gpst: \"2024-06-24 08:20:00\"\n"
         "trajectory: {type: flight, pattern: lawnmower, height_m: 20, length_m: 250, speed_mps: 8,\n"
         "             climb_rate_mps: 3, rows: 2, row_spacing_m: 40, heading_deg: 240, wobble_deg: 0.3}\n"
         "imu: {rate_hz: 250}\n"
         "cameras:\n"
         "  rate_hz: 20\n"
         "  output: features\n"
         "  list:\n"
         "    - {name: cam0, look: down, position_m: [0.06, 0.06, -0.04], mount_rpy_deg: [0.4, -0.3, 0.2]}\n" +
         tail;
}

}  // namespace gvins::fusion::test
