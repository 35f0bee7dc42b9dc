// Error raised while decoding or encoding the contents of one RTCM 3 message: names the data
// field (e.g. "DF405 fine pseudorange") and what was wrong. The decoder turns it into a
// gvins::ParseError (or an error record) carrying the stream name and the frame's byte offset.
#pragma once

#include <stdexcept>
#include <string>

namespace gvins::rtcm {

class MessageError : public std::runtime_error {
 public:
  MessageError(std::string field, const std::string& what)
      : std::runtime_error(field + ": " + what), field_(std::move(field)) {}
  const std::string& field() const { return field_; }

 private:
  std::string field_;
};

}  // namespace gvins::rtcm
