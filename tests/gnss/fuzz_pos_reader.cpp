// libFuzzer target for the .pos reader: any input parses or throws ParseError.
#include <cstdint>
#include <string_view>

#include "gvins/base/parse_error.hpp"
#include "gvins/gnss/pos_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    gvins::parsePosText(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.pos");
  } catch (const gvins::ParseError&) {
  }
  return 0;
}
