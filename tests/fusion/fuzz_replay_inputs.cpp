// libFuzzer target: the replay's own parsers, chosen by the first byte modulo 4 — 0: feature
// track CSV, 1: gvins-replay YAML configuration, 2: ECEF truth CSV (antenna track), 3: the
// gvins-sim dataset.yaml keys gvins-replay reads. Any exception other than gvins::ParseError, or
// any crash/hang, is a bug.
#include <cstdint>
#include <string_view>

#include "gvins/base/parse_error.hpp"
#include "gvins/fusion/replay_config.hpp"
#include "gvins/fusion/replay_feature_tracks.hpp"
#include "gvins/fusion/replay_pipeline.hpp"
#include "gvins/fusion/sim_dataset_info.hpp"

#include "../fuzz/parse_error_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    switch (data[0] % 4) {
      case 0:
        gvins::fusion::parseFeatureTracksCsv(text, "features.csv");
        break;
      case 1:
        gvins::fusion::parseReplayConfig(text, "replay.yaml");
        break;
      case 2:
        gvins::fusion::parseEcefTruthCsv(text, "groundtruth_ecef.csv");
        break;
      default:
        gvins::fusion::parseSimDatasetInfo(text, "dataset.yaml");
        break;
    }
  } catch (const gvins::ParseError& e) {
    static constexpr const char* kFiles[] = {"features.csv", "replay.yaml", "groundtruth_ecef.csv", "dataset.yaml"};
    gvins::fuzz::checkParseError(e, kFiles[data[0] % 4], text);
  }
  return 0;
}
