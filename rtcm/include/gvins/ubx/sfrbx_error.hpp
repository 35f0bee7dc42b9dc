// Error raised while parsing or decoding a UBX-RXM-SFRBX message: names the field (e.g.
// "numWords", "GPS subframe 2 word 3") and what was wrong. The caller that knows the file and
// byte offset turns it into a gvins::ParseError.
#pragma once

#include <stdexcept>
#include <string>

namespace gvins::ubx {

class SfrbxError : public std::runtime_error {
 public:
  SfrbxError(std::string field, const std::string& what)
      : std::runtime_error(field + ": " + what), field_(std::move(field)) {}
  const std::string& field() const { return field_; }

 private:
  std::string field_;
};

}  // namespace gvins::ubx
