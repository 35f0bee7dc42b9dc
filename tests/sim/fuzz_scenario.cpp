// libFuzzer target: gvins-sim scenario YAML (parseScenario, including the `gnss:` section read
// by parseGnssSimConfig). Any exception other than gvins::ParseError, any crash or hang is a bug.
// Parsing opens no file: paths in the scenario are only resolved, not read.
#include <cstdint>
#include <string>

#include "gvins/base/parse_error.hpp"
#include "gvins/sim/scenario.hpp"

#include "../fuzz/parse_error_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const gvins::sim::Scenario sc = gvins::sim::parseScenario(text, "fuzz.yaml");
    (void)sc;
  } catch (const gvins::ParseError& e) {
    gvins::fuzz::checkParseError(e, "fuzz.yaml", text);
  }
  return 0;
}
