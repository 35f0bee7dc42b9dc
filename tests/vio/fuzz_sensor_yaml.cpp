// libFuzzer target: EuRoC sensor.yaml (camera, IMU) and Kalibr camchain/imu YAML parsing. The
// first byte selects the parser. Any exception other than gvins::ParseError is a bug.
#include <cstdint>
#include <string_view>

#include "gvins/base/parse_error.hpp"
#include "gvins/vio/sensor_yaml.hpp"

#include "../fuzz/parse_error_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    switch (data[0] % 3) {
      case 0:
        gvins::vio::parseCameraSensorYaml(text, "sensor.yaml");
        break;
      case 1:
        gvins::vio::parseImuSensorYaml(text, "sensor.yaml");
        break;
      default:
        gvins::vio::parseKalibrCamchain(text, "camchain.yaml");
        break;
    }
  } catch (const gvins::ParseError& e) {
    gvins::fuzz::checkParseError(e, data[0] % 3 == 2 ? "camchain.yaml" : "sensor.yaml", text);
  }
  return 0;
}
