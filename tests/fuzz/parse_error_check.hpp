// The contract every text parser's ParseError keeps, checked by the fuzz targets: it names the
// file it was given, a line of the input (0 when none applies; a line missing at the end of the
// file is named by the number it would have had) and a reason.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "gvins/base/parse_error.hpp"

namespace gvins::fuzz {

inline void checkParseError(const ParseError& e, std::string_view file, std::string_view text) {
  // Line ends: LF, CR LF or a lone CR, so the count of both, plus the last line without a line
  // end and the missing line after it, bounds the line numbers.
  const auto breaks = std::count(text.begin(), text.end(), '\n') + std::count(text.begin(), text.end(), '\r');
  if (e.file() != file || e.line() < 0 || e.line() > static_cast<std::int64_t>(breaks) + 2 || e.reason().empty()) {
    std::abort();
  }
}

}  // namespace gvins::fuzz
