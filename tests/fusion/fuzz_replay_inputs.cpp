// libFuzzer target: the replay's own parsers — feature track CSV (first byte even) and the
// gvins-replay YAML configuration (first byte odd). Any exception other than gvins::ParseError, or
// any crash/hang, is a bug.
#include <cstdint>
#include <string_view>

#include "gvins/base/parse_error.hpp"
#include "gvins/fusion/replay_config.hpp"
#include "gvins/fusion/replay_feature_tracks.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    if (data[0] % 2 == 0) {
      gvins::fusion::parseFeatureTracksCsv(text, "features.csv");
    } else {
      gvins::fusion::parseReplayConfig(text, "replay.yaml");
    }
  } catch (const gvins::ParseError&) {
  }
  return 0;
}
