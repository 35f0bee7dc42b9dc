// Conversions between GVINS bag messages and our types; see rosbag_convert.hpp.
#include "gvins/fusion/rosbag_convert.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "gvins/base/parse_error.hpp"
#include "gvins/base/signal.hpp"
#include "gvins/vio/image_io.hpp"

namespace gvins::fusion {
namespace {

// gnss_comm numbering (gnss_constant.hpp): per system count of numbers, in this order.
constexpr std::uint32_t kGps = 32, kGlo = 27, kGal = 38, kBds = 63;

// RTKLIB obs code numbers 1..48 (rtklib.h CODE_L1C .. CODE_L1Q; the table of code strings in
// rtkcmn.c, "obscodes").
constexpr std::array<const char*, 49> kRtklibCodes = {
    "",   "1C", "1P", "1W", "1Y", "1M", "1N", "1S", "1L", "1E",  //  0- 9
    "1A", "1B", "1X", "1Z", "2C", "2D", "2S", "2L", "2X", "2P",  // 10-19
    "2W", "2Y", "2M", "2N", "5I", "5Q", "5X", "7I", "7Q", "7X",  // 20-29
    "6A", "6B", "6C", "6X", "6Z", "6S", "6L", "8L", "8Q", "8X",  // 30-39
    "2I", "2Q", "6I", "6Q", "3I", "3Q", "3X", "1I", "1Q"};       // 40-48

[[noreturn]] void fail(std::string_view source, const std::string& field, const std::string& why) {
  throw ParseError(std::string(source), 0, field, why);
}

bool checkedGnssTime(const ros::GnssTimeMsg& t, GpsTime& out) {
  if (!std::isfinite(t.tow) || t.tow < -1.0 || t.tow > kSecondsPerWeek + 1.0 || t.week > 20000) return false;
  out = GpsTime::fromWeekTow(static_cast<int>(t.week), t.tow);
  return true;
}

ros::GnssTimeMsg toGnssTime(const GpsTime& t) {
  return {static_cast<std::uint32_t>(t.week()), t.tow()};
}

bool measured(double v) { return v != 0.0 && std::isfinite(v); }

}  // namespace

std::optional<SatId> satFromGnssComm(std::uint32_t sat) {
  if (sat == 0) return std::nullopt;
  std::uint32_t n = sat;
  if (n <= kGps) return SatId(System::Gps, static_cast<int>(n));
  n -= kGps;
  if (n <= kGlo) return SatId(System::Glonass, static_cast<int>(n));
  n -= kGlo;
  if (n <= kGal) {
    SatId s(System::Galileo, static_cast<int>(n));
    return s.valid() ? std::optional<SatId>(s) : std::nullopt;
  }
  n -= kGal;
  if (n <= kBds) return SatId(System::BeiDou, static_cast<int>(n));
  return std::nullopt;
}

std::uint32_t gnssCommSat(SatId s) {
  if (!s.valid()) return 0;
  switch (s.system) {
    case System::Gps: return s.prn;
    case System::Glonass: return kGps + s.prn;
    case System::Galileo: return kGps + kGlo + s.prn;
    case System::BeiDou: return kGps + kGlo + kGal + s.prn;
    default: return 0;
  }
}

std::optional<ObsCode> obsCodeFromRtklib(std::uint8_t code) {
  if (code == 0 || code >= kRtklibCodes.size()) return std::nullopt;
  return ObsCode(kRtklibCodes[code][0], kRtklibCodes[code][1]);
}

std::uint8_t rtklibCode(ObsCode code) {
  for (std::size_t i = 1; i < kRtklibCodes.size(); ++i)
    if (kRtklibCodes[i][0] == code.band && kRtklibCodes[i][1] == code.attr) return static_cast<std::uint8_t>(i);
  return 0;
}

std::optional<BandOfFrequency> bandFromFrequency(System sys, double hz) {
  if (!std::isfinite(hz) || hz <= 0.0) return std::nullopt;
  constexpr double kTol = 1e3;
  if (sys == System::Glonass) {
    // FDMA: f = 1602 MHz + k 0.5625 MHz (G1), 1246 MHz + k 0.4375 MHz (G2), GLONASS ICD 5.1 3.3.1.4.
    const std::pair<char, std::pair<double, double>> fdma[] = {{'1', {1602e6, 0.5625e6}}, {'2', {1246e6, 0.4375e6}}};
    for (const auto& [band, f] : fdma) {
      const double k = (hz - f.first) / f.second;
      const double kr = std::round(k);
      if (kr >= -7 && kr <= 6 && std::abs(hz - (f.first + kr * f.second)) < kTol)
        return BandOfFrequency{band, static_cast<int>(kr)};
    }
  }
  for (char band : std::string_view("123456789")) {
    if (!isKnownBand(sys, band)) continue;
    if (sys == System::Glonass && (band == '1' || band == '2')) continue;
    const auto f = carrierFrequency(sys, band);
    if (f && std::abs(*f - hz) < kTol) return BandOfFrequency{band, std::nullopt};
  }
  return std::nullopt;
}

ObsEpoch toObsEpoch(const ros::GnssMeasMsg& msg, std::string_view source, BagConvertStats* stats,
                    GlonassChannels* channels) {
  BagConvertStats local;
  BagConvertStats& st = stats ? *stats : local;
  ObsEpoch epoch;
  bool haveTime = false;
  for (std::size_t i = 0; i < msg.meas.size(); ++i) {
    const ros::GnssObsMsg& o = msg.meas[i];
    const std::string f = "meas[" + std::to_string(i) + "]";
    GpsTime t;
    if (!checkedGnssTime(o.time, t))
      fail(source, f + ".time", "GPS week " + std::to_string(o.time.week) + " / tow " + std::to_string(o.time.tow) +
                                    " is out of range");
    if (!haveTime) {
      epoch.time = t;
      haveTime = true;
    } else if (std::abs(t - epoch.time) > 1e-9) {
      fail(source, f + ".time", "differs from meas[0].time by " + std::to_string(t - epoch.time) + " s");
    }
    const std::size_t n = o.freqs.size();
    const auto check = [&](std::size_t size, const char* name, bool mayBeEmpty) {
      if (size != n && !(mayBeEmpty && size == 0))
        fail(source, f + "." + name, "has " + std::to_string(size) + " entries but freqs has " + std::to_string(n));
    };
    check(o.cn0.size(), "CN0", false);
    check(o.lli.size(), "LLI", false);
    check(o.code.size(), "code", false);
    check(o.psr.size(), "psr", false);
    check(o.cp.size(), "cp", false);
    check(o.dopp.size(), "dopp", false);
    check(o.psrStd.size(), "psr_std", true);
    check(o.cpStd.size(), "cp_std", true);
    check(o.doppStd.size(), "dopp_std", true);
    check(o.status.size(), "status", true);
    const auto sat = satFromGnssComm(o.sat);
    if (!sat) {
      ++st.unknownSatellites;
      continue;
    }
    SatObs* so = nullptr;
    for (std::size_t j = 0; j < n; ++j) {
      const auto bf = bandFromFrequency(sat->system, o.freqs[j]);
      if (!bf) {
        ++st.unknownSignals;
        continue;
      }
      if (bf->glonassChannel && channels) channels->set(sat->prn, *bf->glonassChannel);
      ObsCode code(bf->band, attributePriority(sat->system, bf->band).empty()
                                 ? 'X'
                                 : attributePriority(sat->system, bf->band).front());
      if (const auto c = obsCodeFromRtklib(o.code[j])) {
        // RTKLIB 2.4.2 wrote BeiDou B1I as "1I" (RINEX 3.02 usage); the frequency decides.
        const ObsCode nc = normalizeObsCode(sat->system, *c, 3.02);
        if (c->band == bf->band)
          code = *c;
        else if (nc.band == bf->band)
          code = nc;
      }
      if (!so) so = &epoch.add(*sat);
      if (so->find(code)) {
        ++st.duplicateSignals;
        continue;
      }
      SignalObs s;
      s.code = code;
      if (measured(o.psr[j])) s.setCode(o.psr[j]);
      if (measured(o.cp[j])) s.setPhase(o.cp[j]);
      if (measured(o.dopp[j])) s.setDoppler(o.dopp[j]);
      if (measured(o.cn0[j])) s.setSnr(o.cn0[j]);
      s.lli = static_cast<std::uint8_t>(o.lli[j] & 0x07);
      // The layout has no signal strength indicator: derive it from C/N0 as RINEX 3.04 (5.7)
      // maps dB-Hz to 1..9 (min(max(floor(C/N0 / 6), 1), 9)).
      if (s.hasSnr()) s.ssi = static_cast<std::uint8_t>(std::clamp(std::floor(s.snr / 6.0), 1.0, 9.0));
      so->signals.push_back(s);
    }
  }
  return epoch;
}

ros::GnssMeasMsg toGnssMeasMsg(const ObsEpoch& epoch, const GlonassChannels& channels, BagConvertStats* stats) {
  BagConvertStats local;
  BagConvertStats& st = stats ? *stats : local;
  ros::GnssMeasMsg msg;
  const ros::GnssTimeMsg t = toGnssTime(epoch.time);
  for (const SatObs& so : epoch.sats) {
    const std::uint32_t satNo = gnssCommSat(so.sat);
    if (satNo == 0) {
      ++st.unknownSatellites;
      continue;
    }
    ros::GnssObsMsg o;
    o.time = t;
    o.sat = satNo;
    for (const SignalObs& s : so.signals) {
      std::optional<int> k;
      if (so.sat.system == System::Glonass) k = channels.get(so.sat.prn);
      const auto f = carrierFrequency(so.sat.system, s.code.band, k);
      if (!f) {
        if (so.sat.system == System::Glonass && !k && (s.code.band == '1' || s.code.band == '2'))
          ++st.glonassNoChannel;
        else
          ++st.unknownSignals;
        continue;
      }
      o.freqs.push_back(*f);
      o.cn0.push_back(s.hasSnr() ? s.snr : 0.0);
      o.lli.push_back(s.lli);
      o.code.push_back(rtklibCode(s.code));
      o.psr.push_back(s.hasCode() ? s.pseudorange : 0.0);
      o.psrStd.push_back(0.0);
      o.cp.push_back(s.hasPhase() ? s.carrierPhase : 0.0);
      o.cpStd.push_back(0.0);
      o.dopp.push_back(s.hasDoppler() ? s.doppler : 0.0);
      o.doppStd.push_back(0.0);
      o.status.push_back(static_cast<std::uint8_t>((s.hasCode() ? 1 : 0) | (s.hasPhase() ? 2 : 0)));
    }
    if (!o.freqs.empty()) msg.meas.push_back(std::move(o));
  }
  return msg;
}

KeplerEphemeris toKeplerEphemeris(const ros::GnssEphemMsg& m, std::string_view source) {
  const auto sat = satFromGnssComm(m.sat);
  if (!sat || sat->system == System::Glonass)
    fail(source, "sat", "satellite number " + std::to_string(m.sat) + " is no GPS/Galileo/BeiDou satellite");
  KeplerEphemeris e;
  e.sat = *sat;
  switch (sat->system) {
    case System::Galileo: e.message = galileoMessageFromDataSources(static_cast<int>(m.code)); break;
    case System::BeiDou: e.message = isBeiDouGeo(*sat) ? NavMessage::BeiDouD2 : NavMessage::BeiDouD1; break;
    default: e.message = NavMessage::GpsLnav; break;
  }
  if (!checkedGnssTime(m.toe, e.toe)) fail(source, "toe", "GPS week/tow out of range");
  if (!checkedGnssTime(m.toc, e.toc)) fail(source, "toc", "GPS week/tow out of range");
  if (!checkedGnssTime(m.ttr, e.ttr)) fail(source, "ttr", "GPS week/tow out of range");
  if (!(m.a > 0.0) || !std::isfinite(m.a)) fail(source, "A", "semi-major axis " + std::to_string(m.a) + " is not positive");
  if (m.week > 20000) fail(source, "week", "week " + std::to_string(m.week) + " out of range");
  e.toeSeconds = m.toeTow;
  e.week = static_cast<int>(m.week);
  e.iode = static_cast<int>(m.iode);
  e.iodc = static_cast<int>(m.iodc);
  e.health = static_cast<int>(m.health);
  e.codesOnL2 = static_cast<int>(m.code);
  e.ura = m.ura;
  e.sqrtA = std::sqrt(m.a);
  e.e = m.e;
  e.i0 = m.i0;
  e.omega0 = m.omg0;
  e.omega = m.omg;
  e.m0 = m.m0;
  e.deltaN = m.deltaN;
  e.omegaDot = m.omgDot;
  e.iDot = m.iDot;
  e.cuc = m.cuc;
  e.cus = m.cus;
  e.crc = m.crc;
  e.crs = m.crs;
  e.cic = m.cic;
  e.cis = m.cis;
  e.af0 = m.af0;
  e.af1 = m.af1;
  e.af2 = m.af2;
  e.tgd = {m.tgd0, m.tgd1};
  return e;
}

ros::GnssEphemMsg toGnssEphemMsg(const KeplerEphemeris& e) {
  ros::GnssEphemMsg m;
  m.sat = gnssCommSat(e.sat);
  m.ttr = toGnssTime(e.ttr);
  m.toe = toGnssTime(e.toe);
  m.toc = toGnssTime(e.toc);
  m.toeTow = e.toeSeconds;
  m.week = static_cast<std::uint32_t>(e.week);
  m.iode = static_cast<std::uint32_t>(e.iode);
  m.iodc = static_cast<std::uint32_t>(e.iodc);
  m.health = static_cast<std::uint32_t>(e.health);
  m.code = static_cast<std::uint32_t>(e.codesOnL2);
  m.ura = e.ura;
  m.a = e.sqrtA * e.sqrtA;
  m.e = e.e;
  m.i0 = e.i0;
  m.omg = e.omega;
  m.omg0 = e.omega0;
  m.m0 = e.m0;
  m.deltaN = e.deltaN;
  m.omgDot = e.omegaDot;
  m.iDot = e.iDot;
  m.cuc = e.cuc;
  m.cus = e.cus;
  m.crc = e.crc;
  m.crs = e.crs;
  m.cic = e.cic;
  m.cis = e.cis;
  m.af0 = e.af0;
  m.af1 = e.af1;
  m.af2 = e.af2;
  m.tgd0 = e.tgd[0];
  m.tgd1 = e.tgd[1];
  return m;
}

GlonassEphemeris toGlonassEphemeris(const ros::GnssGloEphemMsg& m, std::string_view source) {
  const auto sat = satFromGnssComm(m.sat);
  if (!sat || sat->system != System::Glonass)
    fail(source, "sat", "satellite number " + std::to_string(m.sat) + " is no GLONASS satellite");
  if (m.freqo < -7 || m.freqo > 6) fail(source, "freqo", "channel " + std::to_string(m.freqo) + " outside -7..6");
  GlonassEphemeris e;
  e.sat = *sat;
  e.frequencyChannel = m.freqo;
  if (!checkedGnssTime(m.toe, e.toe)) fail(source, "toe", "GPS week/tow out of range");
  if (!checkedGnssTime(m.ttr, e.tof)) fail(source, "ttr", "GPS week/tow out of range");
  e.iode = static_cast<int>(m.iode);
  e.health = static_cast<int>(m.health);
  e.age = static_cast<int>(m.age);
  e.accuracy = m.ura;
  e.position = Eigen::Vector3d(m.pos[0], m.pos[1], m.pos[2]);
  e.velocity = Eigen::Vector3d(m.vel[0], m.vel[1], m.vel[2]);
  e.acceleration = Eigen::Vector3d(m.acc[0], m.acc[1], m.acc[2]);
  e.tauN = m.tauN;
  e.gammaN = m.gamma;
  e.deltaTauN = m.deltaTauN;
  return e;
}

ros::GnssGloEphemMsg toGnssGloEphemMsg(const GlonassEphemeris& e) {
  ros::GnssGloEphemMsg m;
  m.sat = gnssCommSat(e.sat);
  m.ttr = toGnssTime(e.tof);
  m.toe = toGnssTime(e.toe);
  m.freqo = e.frequencyChannel;
  m.iode = static_cast<std::uint32_t>(e.iode);
  m.health = static_cast<std::uint32_t>(e.health);
  m.age = static_cast<std::uint32_t>(e.age);
  m.ura = e.accuracy;
  for (int i = 0; i < 3; ++i) {
    m.pos[i] = e.position[i];
    m.vel[i] = e.velocity[i];
    m.acc[i] = e.acceleration[i];
  }
  m.tauN = e.tauN;
  m.gamma = e.gammaN;
  m.deltaTauN = e.deltaTauN;
  return m;
}

std::int64_t toNanoseconds(const ros::Time& t) {
  return static_cast<std::int64_t>(t.sec) * 1'000'000'000 + static_cast<std::int64_t>(t.nsec);
}

ros::Time toRosTime(std::int64_t ns) {
  if (ns < 0 || ns / 1'000'000'000 > 0xFFFFFFFFLL) throw std::out_of_range("time stamp outside the range of ROS time");
  return {static_cast<std::uint32_t>(ns / 1'000'000'000), static_cast<std::uint32_t>(ns % 1'000'000'000)};
}

vio::ImuSample toImuSample(const ros::ImuMsg& m) {
  vio::ImuSample s;
  s.t_ns = toNanoseconds(m.header.stamp);
  s.gyro = Eigen::Vector3d(m.angularVelocity[0], m.angularVelocity[1], m.angularVelocity[2]);
  s.accel = Eigen::Vector3d(m.linearAcceleration[0], m.linearAcceleration[1], m.linearAcceleration[2]);
  return s;
}

ros::ImuMsg toImuMsg(const vio::ImuSample& s, std::uint32_t seq, const std::string& frameId) {
  ros::ImuMsg m;
  m.header.seq = seq;
  m.header.stamp = toRosTime(s.t_ns);
  m.header.frameId = frameId;
  // Orientation not provided: covariance[0] = -1 (sensor_msgs/Imu.msg convention).
  m.orientationCovariance[0] = -1.0;
  for (int i = 0; i < 3; ++i) {
    m.angularVelocity[i] = s.gyro[i];
    m.linearAcceleration[i] = s.accel[i];
  }
  return m;
}

cv::Mat toMat(const ros::ImageMsg& m, std::string_view source) {
  int type = -1, channels = 1, bytesPerChannel = 1;
  bool swapRb = false;
  if (m.encoding == "mono8" || m.encoding == "8UC1") type = CV_8UC1;
  else if (m.encoding == "mono16" || m.encoding == "16UC1") type = CV_16UC1, bytesPerChannel = 2;
  else if (m.encoding == "bgr8" || m.encoding == "8UC3") type = CV_8UC3, channels = 3;
  else if (m.encoding == "rgb8") type = CV_8UC3, channels = 3, swapRb = true;
  else if (m.encoding == "bgra8" || m.encoding == "8UC4") type = CV_8UC4, channels = 4;
  else if (m.encoding == "rgba8") type = CV_8UC4, channels = 4, swapRb = true;
  else fail(source, "encoding", "unsupported image encoding '" + m.encoding + "'");
  if (bytesPerChannel == 2 && m.isBigEndian) fail(source, "is_bigendian", "big-endian 16-bit images are not supported");
  if (m.width == 0 || m.height == 0 || m.width > 20000 || m.height > 20000)
    fail(source, "width/height", std::to_string(m.width) + "x" + std::to_string(m.height) + " is no usable image size");
  const std::uint64_t rowBytes = static_cast<std::uint64_t>(m.width) * channels * bytesPerChannel;
  if (m.step < rowBytes) fail(source, "step", "step " + std::to_string(m.step) + " < row size " + std::to_string(rowBytes));
  if (static_cast<std::uint64_t>(m.step) * m.height != m.data.size())
    fail(source, "data", "has " + std::to_string(m.data.size()) + " bytes, step x height = " +
                             std::to_string(static_cast<std::uint64_t>(m.step) * m.height));
  cv::Mat out(static_cast<int>(m.height), static_cast<int>(m.width), type);
  for (std::uint32_t r = 0; r < m.height; ++r)
    std::memcpy(out.ptr(static_cast<int>(r)), m.data.data() + static_cast<std::size_t>(r) * m.step, rowBytes);
  if (swapRb) cv::cvtColor(out, out, channels == 3 ? cv::COLOR_RGB2BGR : cv::COLOR_RGBA2BGRA);
  return out;
}

ros::ImageMsg toImageMsg(const cv::Mat& image, std::int64_t t_ns, std::uint32_t seq, const std::string& frameId) {
  ros::ImageMsg m;
  m.header.seq = seq;
  m.header.stamp = toRosTime(t_ns);
  m.header.frameId = frameId;
  switch (image.type()) {
    case CV_8UC1: m.encoding = "mono8"; break;
    case CV_16UC1: m.encoding = "mono16"; break;
    case CV_8UC3: m.encoding = "bgr8"; break;
    default: throw std::invalid_argument("toImageMsg: only CV_8UC1, CV_16UC1 and CV_8UC3 images");
  }
  m.height = static_cast<std::uint32_t>(image.rows);
  m.width = static_cast<std::uint32_t>(image.cols);
  const std::size_t rowBytes = static_cast<std::size_t>(image.cols) * image.elemSize();
  m.step = static_cast<std::uint32_t>(rowBytes);
  m.data.resize(rowBytes * static_cast<std::size_t>(image.rows));
  for (int r = 0; r < image.rows; ++r) std::memcpy(m.data.data() + rowBytes * static_cast<std::size_t>(r), image.ptr(r), rowBytes);
  return m;
}

cv::Mat toMat(const ros::CompressedImageMsg& m, std::string_view source) {
  return vio::decodeGrayImage(m.data, std::string(source));
}

}  // namespace gvins::fusion
