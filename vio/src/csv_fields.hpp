// Private helpers of the EuRoC/TUM text readers: splitting a delimited line into fields and
// parsing integer-nanosecond time stamps exactly (a double cannot hold 19 significant digits).
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "gvins/base/text_fields.hpp"

namespace gvins::vio::detail {

/// Splits at commas (CSV) or at runs of blanks/tabs (whitespace = true); fields are trimmed.
void splitFields(std::string_view line, bool whitespace, std::vector<std::string_view>& out);

/// True for lines to skip: empty/blank or starting with '#'.
bool isCommentOrBlank(std::string_view line);

/// Non-negative integer nanoseconds, optionally followed by a fractional part (".0000"), which
/// is rounded to the nearest nanosecond. Throws ParseError on anything else or overflow.
std::int64_t parseNanoseconds(std::string_view text, const TextLocation& where, std::string_view field);

/// Seconds with up to 9 decimals (more are rounded), parsed exactly into nanoseconds.
std::int64_t parseSecondsToNanoseconds(std::string_view text, const TextLocation& where,
                                       std::string_view field);

}  // namespace gvins::vio::detail
