// Fixed-column text fields as used by RINEX: cut a column range out of a line and convert it,
// throwing ParseError with file, line and field name when the text is not a number.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "gvins/base/parse_error.hpp"

namespace gvins {

/// Where a line came from, for error messages.
struct TextLocation {
  std::string_view file;
  std::int64_t line = 0;
};

/// Columns [pos, pos+len) of a line, clipped to the line (short lines are common in RINEX);
/// trailing '\r' is ignored.
std::string_view column(std::string_view line, std::size_t pos, std::size_t len);
/// Column without leading/trailing blanks.
std::string_view trimmedColumn(std::string_view line, std::size_t pos, std::size_t len);
std::string_view trim(std::string_view s);

/// Parses a floating-point field; Fortran 'D'/'d' exponents are accepted. A blank field yields
/// std::nullopt; anything that is not a number throws ParseError naming `field`.
std::optional<double> parseOptionalDouble(std::string_view text, const TextLocation& where,
                                          std::string_view field);
/// The common short form of a decimal number without a conversion call: [sign] digits [. digits]
/// [E|e|D|d [sign] 1-3 digits] (at least one mantissa digit, no blanks) with at most 19
/// mantissa digits forming an integer M <= 2^53 and a decimal exponent k of M 10^k within
/// -22..22. M and 10^|k| are exact doubles, so the one multiplication or division is correctly
/// rounded: the value is the one strtod / std::from_chars give. Returns false (v unchanged) for
/// anything else, which the caller parses the general way.
bool parseShortDecimal(std::string_view text, double& v);
/// As parseOptionalDouble but a blank field is an error too.
double parseDouble(std::string_view text, const TextLocation& where, std::string_view field);
/// As parseDouble, and NaN or infinity ("nan", "inf", overflow) is an error too.
double parseFiniteDouble(std::string_view text, const TextLocation& where, std::string_view field);
/// Blank means `blankValue`.
double parseDoubleOr(std::string_view text, double blankValue, const TextLocation& where,
                     std::string_view field);

/// Integer fields, same rules.
std::optional<long> parseOptionalInt(std::string_view text, const TextLocation& where,
                                     std::string_view field);
long parseInt(std::string_view text, const TextLocation& where, std::string_view field);

/// Throws ParseError at `where` for `field`.
[[noreturn]] void throwParseError(const TextLocation& where, std::string_view field,
                                  const std::string& what);

}  // namespace gvins
