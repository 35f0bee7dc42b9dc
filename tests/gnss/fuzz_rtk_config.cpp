// libFuzzer target for the RTK YAML options: any input parses or throws ParseError.
#include <cstdint>
#include <string_view>

#include "gvins/base/parse_error.hpp"
#include "gvins/gnss/rtk_config.hpp"

#include "../fuzz/parse_error_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    gvins::parseRtkConfig(text, "fuzz.yaml");
  } catch (const gvins::ParseError& e) {
    gvins::fuzz::checkParseError(e, "fuzz.yaml", text);
  }
  return 0;
}
