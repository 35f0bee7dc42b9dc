// libFuzzer target for the .pos reader: any input parses or throws ParseError.
#include <cstdint>
#include <string_view>

#include "gvins/base/parse_error.hpp"
#include "gvins/gnss/pos_reader.hpp"

#include "../fuzz/parse_error_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    gvins::parsePosText(text, "fuzz.pos");
  } catch (const gvins::ParseError& e) {
    gvins::fuzz::checkParseError(e, "fuzz.pos", text);
  }
  return 0;
}
