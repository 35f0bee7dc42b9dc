// Conversions between the GVINS bag messages (rosbag_messages.hpp) and our types: gnss_comm
// satellite numbers and RTKLIB-style code numbers, GnssMeasMsg <-> ObsEpoch, GnssEphemMsg <->
// KeplerEphemeris, GnssGloEphemMsg <-> GlonassEphemeris, Imu <-> vio::ImuSample, Image <-> cv::Mat.
//
// Facts used (no code taken from the projects):
// * gnss_comm numbers satellites consecutively over GPS 1-32, GLONASS 1-27, Galileo 1-38, BeiDou
//   1-63 (gnss_comm gnss_constant.hpp MIN/MAX_PRN_*, sat_no() in gnss_utility.cpp): G01 = 1,
//   R01 = 33, E01 = 60, C01 = 98, C63 = 160. Other systems are not representable.
// * GnssObsMsg.code holds RTKLIB's CODE_* numbers (rtklib.h: 1 = "1C", 2 = "1P", ... 40 = "2I").
//   The band is taken from the frequency (freqs[], Hz), which is authoritative; the code gives the
//   tracking attribute when its band agrees, otherwise the best attribute of the band is assumed.
// * GnssTimeMsg is GPS week and time of week (gnss_comm gnss_ros.cpp writes every time, also
//   ephemeris toe/toc/ttr of BeiDou and Galileo, through time2gpst). Ephemeris `A` is the
//   semi-major axis (m), `toe_tow`/`week` are in the system's own week count, `tau_n` is the
//   ICD tauN, `freqo` the FDMA channel.
// * A value of exactly 0 means "not measured" for psr, cp, dopp and CN0 (the u-blox driver of
//   GVINS leaves unmeasured entries at 0); status bit 0/1 mark a valid pseudorange/phase.
//   Our writer sets them accordingly. The RINEX signal strength indicator is not carried; the
//   reader derives it from C/N0 with the RINEX 3.04 mapping.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include <opencv2/core/mat.hpp>

#include "gvins/base/observation.hpp"
#include "gvins/ephemeris/glonass_ephemeris.hpp"
#include "gvins/ephemeris/kepler_ephemeris.hpp"
#include "gvins/fusion/rosbag_messages.hpp"
#include "gvins/vio/imu_sample.hpp"

namespace gvins::fusion {

/// gnss_comm satellite number -> SatId (nullopt for 0, out of range or a Galileo PRN above 36).
std::optional<SatId> satFromGnssComm(std::uint32_t sat);
/// SatId -> gnss_comm number; 0 for systems gnss_comm does not number (QZSS, SBAS, NavIC).
std::uint32_t gnssCommSat(SatId sat);

/// RTKLIB CODE_* number -> RINEX code ("1C"); nullopt for 0 and unknown numbers.
std::optional<ObsCode> obsCodeFromRtklib(std::uint8_t code);
/// RINEX code -> RTKLIB number (0 if it has none).
std::uint8_t rtklibCode(ObsCode code);

/// The RINEX band of a carrier frequency of a system, and for GLONASS FDMA bands the channel.
struct BandOfFrequency {
  char band = '1';
  std::optional<int> glonassChannel;
};
/// nullopt when the frequency is no carrier of the system (tolerance 1 kHz).
std::optional<BandOfFrequency> bandFromFrequency(System sys, double hz);

/// Counts of what a conversion left out.
struct BagConvertStats {
  std::int64_t unknownSatellites = 0;  ///< sat numbers that are no satellite / not representable
  std::int64_t unknownSignals = 0;     ///< frequencies that are no carrier of the system
  std::int64_t duplicateSignals = 0;   ///< a second signal with the same code on one satellite
  std::int64_t glonassNoChannel = 0;   ///< GLONASS FDMA signals without a known channel (writer)
};

/// GnssMeasMsg -> one epoch. All GnssObsMsg must carry the same time (else ParseError); arrays of
/// one satellite must have freqs.size() entries (the *_std and status arrays may be empty).
/// GLONASS channels seen in the frequencies are stored in `channels` when given.
ObsEpoch toObsEpoch(const ros::GnssMeasMsg& msg, std::string_view source, BagConvertStats* stats = nullptr,
                    GlonassChannels* channels = nullptr);
/// One epoch -> GnssMeasMsg (GPS, GLONASS, Galileo, BeiDou; other systems are skipped and counted).
/// GLONASS frequencies need the FDMA channels.
ros::GnssMeasMsg toGnssMeasMsg(const ObsEpoch& epoch, const GlonassChannels& channels,
                               BagConvertStats* stats = nullptr);

/// GnssEphemMsg -> Keplerian record; ParseError (source, field) for an unusable satellite number,
/// a non-positive semi-major axis or a week/tow out of range.
KeplerEphemeris toKeplerEphemeris(const ros::GnssEphemMsg& msg, std::string_view source);
ros::GnssEphemMsg toGnssEphemMsg(const KeplerEphemeris& eph);
GlonassEphemeris toGlonassEphemeris(const ros::GnssGloEphemMsg& msg, std::string_view source);
ros::GnssGloEphemMsg toGnssGloEphemMsg(const GlonassEphemeris& eph);

/// Integer nanoseconds of a ROS time, and back (ParseError-free: a stamp beyond 2106 cannot be
/// represented and throws std::out_of_range).
std::int64_t toNanoseconds(const ros::Time& t);
ros::Time toRosTime(std::int64_t ns);

vio::ImuSample toImuSample(const ros::ImuMsg& msg);
ros::ImuMsg toImuMsg(const vio::ImuSample& s, std::uint32_t seq, const std::string& frameId = "imu4");

/// sensor_msgs/Image -> cv::Mat (mono8 -> CV_8UC1, mono16 -> CV_16UC1, bgr8/rgb8 -> CV_8UC3 in BGR
/// order, bgra8/rgba8 -> CV_8UC4 in BGRA order); the pixels are copied. ParseError for unknown
/// encodings, big-endian 16-bit data, or a step/size that does not match the data.
cv::Mat toMat(const ros::ImageMsg& msg, std::string_view source);
/// CV_8UC1/CV_16UC1/CV_8UC3 (BGR) -> Image (mono8/mono16/bgr8, rows packed).
ros::ImageMsg toImageMsg(const cv::Mat& image, std::int64_t t_ns, std::uint32_t seq,
                         const std::string& frameId = "camera");
/// Decodes a CompressedImage (PNG/JPEG) to 8-bit gray; ParseError if it does not decode.
cv::Mat toMat(const ros::CompressedImageMsg& msg, std::string_view source);

}  // namespace gvins::fusion
