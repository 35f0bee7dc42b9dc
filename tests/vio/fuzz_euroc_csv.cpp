// libFuzzer target: the EuRoC/ASL CSV readers (IMU, camera list, ground truth) and the TUM
// trajectory reader. The first byte selects the reader, the rest is the file content. Any
// exception other than gvins::ParseError, or any crash/hang, is a bug.
#include <cstdint>
#include <string_view>
#include <vector>

#include "gvins/base/parse_error.hpp"
#include "gvins/vio/euroc_csv.hpp"
#include "gvins/vio/tum_trajectory.hpp"

#include "../fuzz/parse_error_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    switch (data[0] % 5) {
      case 0: {
        gvins::vio::ImuCsvReader r(text, "imu.csv", 200.0);
        gvins::vio::ImuSample s;
        while (r.next(s)) {
        }
        break;
      }
      case 1:
        gvins::vio::parseCameraCsv(text, "cam.csv");
        break;
      case 2: {
        gvins::vio::GroundTruthCsvReader r(text, "gt.csv");
        gvins::vio::GroundTruthSample s;
        while (r.next(s)) {
        }
        break;
      }
      case 3: {
        std::vector<std::size_t> marks;
        gvins::vio::parseTumTrajectory(text, "traj.txt", gvins::vio::TumTimeUnit::Seconds, &marks);
        break;
      }
      default:
        gvins::vio::parseTumTrajectory(text, "traj.txt", gvins::vio::TumTimeUnit::Nanoseconds);
        break;
    }
  } catch (const gvins::ParseError& e) {
    static constexpr const char* kFiles[] = {"imu.csv", "cam.csv", "gt.csv", "traj.txt", "traj.txt"};
    gvins::fuzz::checkParseError(e, kFiles[data[0] % 5], text);
  }
  return 0;
}
