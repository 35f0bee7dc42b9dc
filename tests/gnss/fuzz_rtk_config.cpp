// libFuzzer target for the RTK YAML options: any input parses or throws ParseError.
#include <cstdint>
#include <string_view>

#include "gvins/base/parse_error.hpp"
#include "gvins/gnss/rtk_config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    gvins::parseRtkConfig(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.yaml");
  } catch (const gvins::ParseError&) {
  }
  return 0;
}
