// External sensor fusion raw data: UBX-ESF-RAW (0x10 0x03) and UBX-ESF-MEAS (0x10 0x02) to IMU
// samples (u-blox ZED-F9R HPS 1.30 / NEO-M8U interface descriptions, "UBX-ESF-RAW", "UBX-ESF-MEAS"
// and the table of sensor data types). Each data word holds a 24-bit signed value (bits 0-23) and
// its type (bits 24-29): 5 gyro z, 13 gyro y, 14 gyro x (deg/s * 2^-12), 12 gyro temperature
// (deg C * 1e-2), 16/17/18 accelerometer x/y/z (m/s^2 * 2^-10). Other types (wheel ticks, speed)
// are skipped.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace gvins::ubx {

inline constexpr std::uint8_t kClassEsf = 0x10;
inline constexpr std::uint8_t kIdEsfMeas = 0x02;
inline constexpr std::uint8_t kIdEsfRaw = 0x03;

/// One IMU sample in the sensor frame of the receiver.
struct ImuSample {
  /// Sensor time tag as transmitted: ESF-RAW sTtag or ESF-MEAS timeTag (receiver-local ticks,
  /// not GNSS time).
  std::uint32_t timeTag = 0;
  std::array<double, 3> gyro{};   ///< rad/s
  std::array<double, 3> accel{};  ///< m/s^2
  double temperature = 0.0;       ///< deg C (gyro temperature)
  std::uint8_t present = 0;       ///< bits 0-2 gyro x/y/z, 3-5 accel x/y/z, 6 temperature
  bool complete() const { return (present & 0x3F) == 0x3F; }
};

/// ESF-RAW: groups consecutive data words of equal sTtag into one sample each. Throws
/// rtcm::MessageError if the payload is not 4 + 8*N bytes.
std::vector<ImuSample> parseEsfRaw(std::span<const std::uint8_t> payload);
/// ESF-MEAS: one sample from the numMeas data words (flags bits 11-15). Throws
/// rtcm::MessageError if numMeas words do not fit the payload.
ImuSample parseEsfMeas(std::span<const std::uint8_t> payload);

}  // namespace gvins::ubx
