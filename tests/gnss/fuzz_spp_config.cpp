// libFuzzer target for the SPP YAML options: any input parses or throws ParseError.
#include <cstdint>
#include <string_view>

#include "gvins/base/parse_error.hpp"
#include "gvins/gnss/spp_config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    gvins::parseSppConfig(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.yaml");
  } catch (const gvins::ParseError&) {
  }
  return 0;
}
