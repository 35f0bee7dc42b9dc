#include "gvins/base/parse_error.hpp"

namespace gvins {
namespace {
std::string format(const std::string& file, std::int64_t line, const std::string& field,
                   const std::string& what) {
  std::string msg = file.empty() ? std::string("<input>") : file;
  if (line > 0) msg += ":" + std::to_string(line);
  msg += ": ";
  if (!field.empty()) msg += "field '" + field + "': ";
  msg += what;
  return msg;
}
}  // namespace

ParseError::ParseError(std::string file, std::int64_t line, std::string field, const std::string& what)
    : std::runtime_error(format(file, line, field, what)),
      file_(std::move(file)),
      line_(line),
      field_(std::move(field)),
      reason_(what) {}

}  // namespace gvins
