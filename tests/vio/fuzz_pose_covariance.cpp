// libFuzzer target: the pose covariance reader (pose_covariance_csv.hpp). Any exception other than
// gvins::ParseError, or any crash/hang, is a bug.
#include <cstdint>
#include <string_view>

#include "gvins/base/parse_error.hpp"
#include "gvins/vio/pose_covariance_csv.hpp"

#include "../fuzz/parse_error_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    gvins::vio::parsePoseCovarianceCsv(text, "fuzz.cov.csv");
  } catch (const gvins::ParseError& e) {
    gvins::fuzz::checkParseError(e, "fuzz.cov.csv", text);
  }
  return 0;
}
