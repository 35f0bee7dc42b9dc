// libFuzzer target: the estimator's YAML configuration (vio::parseSriSwfConfig, camera paths
// resolved against the bundled EuRoC clip so that valid seeds reach every key) and the GNSS
// fusion's (fusion::parseGnssFusionConfig). The first byte selects the parser. Any exception
// other than gvins::ParseError is a bug.
#include <cstdint>
#include <string>
#include <string_view>

#include "gvins/base/parse_error.hpp"
#include "gvins/fusion/gnss_fusion_config.hpp"
#include "gvins/vio/sri_swf_estimator.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data) + 1, size - 1);
  static const std::string euroc = std::string(GVINS_TEST_DATA) + "/euroc/v101_static_stereo/mav0";
  try {
    if (data[0] % 2 == 0) {
      (void)gvins::vio::parseSriSwfConfig(text, "estimator.yaml", euroc);
    } else {
      (void)gvins::fusion::parseGnssFusionConfig(text, "gnss.yaml");
    }
  } catch (const gvins::ParseError&) {
  }
  return 0;
}
