// The one exception type of all parsers: it names the file, the line (or byte offset for binary
// input) and the field that was wrong.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

namespace gvins {

class ParseError : public std::runtime_error {
 public:
  /// `line` is 1-based (0 when not applicable, e.g. an empty file); `field` names what was being
  /// read ("RINEX VERSION / TYPE", "sqrtA", "epoch month", "CRC", ...).
  ParseError(std::string file, std::int64_t line, std::string field, const std::string& what);

  const std::string& file() const { return file_; }
  std::int64_t line() const { return line_; }
  const std::string& field() const { return field_; }
  /// The message without location ("bad number '1.2.3'").
  const std::string& reason() const { return reason_; }

 private:
  std::string file_;
  std::int64_t line_;
  std::string field_;
  std::string reason_;
};

}  // namespace gvins
