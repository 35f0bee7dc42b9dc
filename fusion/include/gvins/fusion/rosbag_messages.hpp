// ROS 1 message layouts of the GVINS datasets (Cao et al., "GVINS", IEEE T-RO 2022) and their
// serialisation, written here from the message definitions (no ROS code is used):
//   sensor_msgs/Imu, sensor_msgs/Image, sensor_msgs/CompressedImage (ROS common_msgs 1.13),
//   gnss_comm/GnssMeasMsg, GnssObsMsg, GnssTimeMsg, GnssEphemMsg, GnssGloEphemMsg
//   (HKUST-Aerial-Robotics/gnss_comm, msg/*.msg; the field order below follows those files).
// ROS 1 serialisation (wiki.ros.org/msg, "Serialization"): little-endian fixed-size fields in
// declaration order, strings and variable-length arrays as a uint32 count followed by the elements,
// fixed-length arrays (float64[9]) without a count, nested messages inline.
//
// Decoding never trusts a count: every read is checked against the remaining bytes, trailing
// bytes are an error, and every failure is a gvins::ParseError naming the source, the byte offset
// and the field ("meas[3].psr[1]").
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace gvins::fusion::ros {

/// ROS time: seconds and nanoseconds since the Unix epoch (for GVINS bags the stamps are what the
/// recording node put there; our writer uses GPST seconds since 1980-01-06, see rosbag_dataset.hpp).
struct Time {
  std::uint32_t sec = 0;
  std::uint32_t nsec = 0;
  friend bool operator==(const Time&, const Time&) = default;
};

/// std_msgs/Header.
struct Header {
  std::uint32_t seq = 0;
  Time stamp;
  std::string frameId;
  friend bool operator==(const Header&, const Header&) = default;
};

/// sensor_msgs/Imu.
struct ImuMsg {
  Header header;
  std::array<double, 4> orientation{0, 0, 0, 1};  ///< x, y, z, w
  std::array<double, 9> orientationCovariance{};
  std::array<double, 3> angularVelocity{};
  std::array<double, 9> angularVelocityCovariance{};
  std::array<double, 3> linearAcceleration{};
  std::array<double, 9> linearAccelerationCovariance{};
  friend bool operator==(const ImuMsg&, const ImuMsg&) = default;
};

/// sensor_msgs/Image.
struct ImageMsg {
  Header header;
  std::uint32_t height = 0;
  std::uint32_t width = 0;
  std::string encoding;  ///< "mono8", "bgr8", "mono16", ...
  std::uint8_t isBigEndian = 0;
  std::uint32_t step = 0;  ///< bytes per row
  std::vector<std::uint8_t> data;
  friend bool operator==(const ImageMsg&, const ImageMsg&) = default;
};

/// sensor_msgs/CompressedImage.
struct CompressedImageMsg {
  Header header;
  std::string format;  ///< "jpeg", "png", "mono8; png compressed", ...
  std::vector<std::uint8_t> data;
  friend bool operator==(const CompressedImageMsg&, const CompressedImageMsg&) = default;
};

/// gnss_comm/GnssTimeMsg: GPS week and time of week (GPST).
struct GnssTimeMsg {
  std::uint32_t week = 0;
  double tow = 0.0;
  friend bool operator==(const GnssTimeMsg&, const GnssTimeMsg&) = default;
};

/// gnss_comm/GnssObsMsg: one satellite's signals of an epoch (parallel arrays, one entry per
/// signal).
struct GnssObsMsg {
  GnssTimeMsg time;
  std::uint32_t sat = 0;  ///< gnss_comm satellite number (see rosbag_convert.hpp)
  std::vector<double> freqs;     ///< Hz
  std::vector<double> cn0;       ///< dB-Hz
  std::vector<std::uint8_t> lli;
  std::vector<std::uint8_t> code;  ///< RTKLIB CODE_* numbering
  std::vector<double> psr, psrStd;  ///< m
  std::vector<double> cp, cpStd;    ///< cycles
  std::vector<double> dopp, doppStd;  ///< Hz
  std::vector<std::uint8_t> status;
  friend bool operator==(const GnssObsMsg&, const GnssObsMsg&) = default;
};

/// gnss_comm/GnssMeasMsg.
struct GnssMeasMsg {
  std::vector<GnssObsMsg> meas;
  friend bool operator==(const GnssMeasMsg&, const GnssMeasMsg&) = default;
};

/// gnss_comm/GnssEphemMsg (GPS, Galileo, BeiDou Keplerian records).
struct GnssEphemMsg {
  std::uint32_t sat = 0;
  GnssTimeMsg ttr, toe, toc;
  double toeTow = 0.0;
  std::uint32_t week = 0, iode = 0, iodc = 0, health = 0, code = 0;
  double ura = 0.0;
  double a = 0.0, e = 0.0, i0 = 0.0, omg = 0.0, omg0 = 0.0, m0 = 0.0, deltaN = 0.0, omgDot = 0.0, iDot = 0.0;
  double cuc = 0.0, cus = 0.0, crc = 0.0, crs = 0.0, cic = 0.0, cis = 0.0;
  double af0 = 0.0, af1 = 0.0, af2 = 0.0, tgd0 = 0.0, tgd1 = 0.0, aDot = 0.0, nDot = 0.0;
  friend bool operator==(const GnssEphemMsg&, const GnssEphemMsg&) = default;
};

/// gnss_comm/GnssGloEphemMsg.
struct GnssGloEphemMsg {
  std::uint32_t sat = 0;
  GnssTimeMsg ttr, toe;
  std::int32_t freqo = 0;
  std::uint32_t iode = 0, health = 0, age = 0;
  double ura = 0.0;
  std::array<double, 3> pos{}, vel{}, acc{};
  double tauN = 0.0, gamma = 0.0, deltaTauN = 0.0;
  friend bool operator==(const GnssGloEphemMsg&, const GnssGloEphemMsg&) = default;
};

/// What a bag's connection record says about a message type.
struct MessageType {
  std::string_view datatype;    ///< "gnss_comm/GnssMeasMsg"
  std::string_view md5sum;      ///< ROS md5 of the definition (checked against the bag)
  std::string_view definition;  ///< full text with the dependent definitions
};

/// The types above. The md5 sums were computed from the definitions with ROS's algorithm (md5 of
/// the definition with comments removed and nested types replaced by their md5); the sums of the
/// std_msgs/sensor_msgs types agree with the published ones, which checks the computation.
const MessageType& imuType();
const MessageType& imageType();
const MessageType& compressedImageType();
const MessageType& gnssMeasType();
const MessageType& gnssEphemType();
const MessageType& gnssGloEphemType();

std::vector<std::uint8_t> serialize(const ImuMsg& m);
std::vector<std::uint8_t> serialize(const ImageMsg& m);
std::vector<std::uint8_t> serialize(const CompressedImageMsg& m);
std::vector<std::uint8_t> serialize(const GnssMeasMsg& m);
std::vector<std::uint8_t> serialize(const GnssEphemMsg& m);
std::vector<std::uint8_t> serialize(const GnssGloEphemMsg& m);

/// Decoders: `source` names the input in errors (e.g. "bag.bag: /imu0 message 12"); `baseOffset`
/// is added to the reported byte offsets (the message's offset in its file when known).
ImuMsg deserializeImu(std::span<const std::uint8_t> bytes, std::string_view source, std::uint64_t baseOffset = 0);
ImageMsg deserializeImage(std::span<const std::uint8_t> bytes, std::string_view source, std::uint64_t baseOffset = 0);
CompressedImageMsg deserializeCompressedImage(std::span<const std::uint8_t> bytes, std::string_view source,
                                              std::uint64_t baseOffset = 0);
GnssMeasMsg deserializeGnssMeas(std::span<const std::uint8_t> bytes, std::string_view source,
                                std::uint64_t baseOffset = 0);
GnssEphemMsg deserializeGnssEphem(std::span<const std::uint8_t> bytes, std::string_view source,
                                  std::uint64_t baseOffset = 0);
GnssGloEphemMsg deserializeGnssGloEphem(std::span<const std::uint8_t> bytes, std::string_view source,
                                        std::uint64_t baseOffset = 0);

}  // namespace gvins::fusion::ros
