// ROS message (de)serialisation of the GVINS bag layouts and their conversion to our types.
// Truth: byte sequences assembled by hand from the ROS 1 serialisation rules and the gnss_comm
// .msg files; gnss_comm's satellite numbering (gnss_constant.hpp: 32 GPS, 27 GLONASS, 38 Galileo,
// 63 BeiDou numbers); carrier frequencies from the ICDs; the bundled Nagoya RINEX files.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <map>

#include <opencv2/core.hpp>

#include "gvins/base/parse_error.hpp"
#include "gvins/base/rinex_obs_reader.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/fusion/rosbag_convert.hpp"
#include "gvins/fusion/rosbag_messages.hpp"

using namespace gvins;
using namespace gvins::fusion;

namespace {

const std::string kData = GVINS_TEST_DATA;

struct Bytes {
  std::vector<std::uint8_t> b;
  Bytes& u32(std::uint32_t v) {
    for (int i = 0; i < 4; ++i) b.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
    return *this;
  }
  Bytes& f64(double v) {
    const auto u = std::bit_cast<std::uint64_t>(v);
    for (int i = 0; i < 8; ++i) b.push_back(static_cast<std::uint8_t>(u >> (8 * i)));
    return *this;
  }
  Bytes& u8(std::uint8_t v) {
    b.push_back(v);
    return *this;
  }
};

ros::GnssObsMsg sampleObs() {
  ros::GnssObsMsg o;
  o.time = {2320, 345600.25};
  o.sat = 33 + 1;  // R02
  o.freqs = {1602e6 - 4 * 0.5625e6, 1246e6 - 4 * 0.4375e6};
  o.cn0 = {45.0, 38.5};
  o.lli = {0, 1};
  o.code = {1, 14};  // "1C", "2C"
  o.psr = {21e6 + 0.123, 21e6 + 1.5};
  o.psrStd = {0.3, 0.6};
  o.cp = {1.1e8 + 0.25, 8.6e7 + 0.5};
  o.cpStd = {0.004, 0.008};
  o.dopp = {-1234.5, -960.125};
  o.doppStd = {0.1, 0.2};
  o.status = {3, 1};
  return o;
}

}  // namespace

TEST(RosbagMessages, GnssMeasBytesFollowTheRosLayout) {
  ros::GnssMeasMsg m;
  ros::GnssObsMsg o;
  o.time = {2317, 0.5};
  o.sat = 5;
  o.freqs = {1575.42e6};
  o.cn0 = {40.0};
  o.lli = {1};
  o.code = {1};
  o.psr = {2.2e7};
  o.psrStd = {};
  o.cp = {1.2e8};
  o.cpStd = {};
  o.dopp = {-100.0};
  o.doppStd = {};
  o.status = {3};
  m.meas.push_back(o);
  Bytes e;
  e.u32(1).u32(2317).f64(0.5).u32(5);
  e.u32(1).f64(1575.42e6).u32(1).f64(40.0).u32(1).u8(1).u32(1).u8(1);
  e.u32(1).f64(2.2e7).u32(0).u32(1).f64(1.2e8).u32(0).u32(1).f64(-100.0).u32(0).u32(1).u8(3);
  EXPECT_EQ(ros::serialize(m), e.b);
  EXPECT_EQ(ros::deserializeGnssMeas(e.b, "hand"), m);
}

TEST(RosbagMessages, ImuAndEphemerisSizesAndFieldPositions) {
  ros::ImuMsg imu;
  imu.header = {7, {1600000000, 5}, "imu"};
  imu.angularVelocity = {0.1, -0.2, 0.3};
  imu.linearAcceleration = {0.0, 0.0, 9.81};
  const auto bytes = ros::serialize(imu);
  // seq 4 + stamp 8 + string 4+3 + quaternion 32 + 3 x (9 covariance + ...) doubles.
  ASSERT_EQ(bytes.size(), 4u + 8 + 7 + 32 + 72 + 24 + 72 + 24 + 72);
  double az;
  std::memcpy(&az, bytes.data() + 4 + 8 + 7 + 32 + 72 + 24 + 72 + 16, 8);
  EXPECT_EQ(az, 9.81);
  EXPECT_EQ(ros::deserializeImu(bytes, "imu"), imu);

  ros::GnssEphemMsg eph;
  eph.sat = 3;
  eph.nDot = 1.25e-13;
  const auto eb = ros::serialize(eph);
  // sat 4 + 3 times 12 + toe_tow 8 + 5 uint32 20 + 23 doubles.
  ASSERT_EQ(eb.size(), 4u + 36 + 8 + 20 + 23 * 8);
  double nDot;
  std::memcpy(&nDot, eb.data() + eb.size() - 8, 8);
  EXPECT_EQ(nDot, 1.25e-13);
  ros::GnssGloEphemMsg glo;
  glo.freqo = -7;
  glo.deltaTauN = 2e-9;
  const auto gb = ros::serialize(glo);
  ASSERT_EQ(gb.size(), 4u + 24 + 4 + 12 + 8 + 9 * 8 + 24);
  std::int32_t k;
  std::memcpy(&k, gb.data() + 28, 4);
  EXPECT_EQ(k, -7);
  EXPECT_EQ(ros::deserializeGnssGloEphem(gb, "glo"), glo);
}

TEST(RosbagMessages, MalformedMessagesNameOffsetAndField) {
  ros::GnssMeasMsg m;
  m.meas = {sampleObs(), sampleObs()};
  const auto good = ros::serialize(m);
  ASSERT_EQ(ros::deserializeGnssMeas(good, "x"), m);
  // Every truncation fails with a ParseError naming the source; none crashes.
  for (std::size_t n = 0; n < good.size(); ++n) {
    const std::span<const std::uint8_t> cut(good.data(), n);
    try {
      ros::deserializeGnssMeas(cut, "cut.bag: message 3", 1000);
      FAIL() << "truncated to " << n << " bytes was accepted";
    } catch (const ParseError& e) {
      EXPECT_EQ(e.file(), "cut.bag: message 3");
      EXPECT_GE(e.line(), 1000);
      EXPECT_LE(e.line(), 1000 + static_cast<std::int64_t>(n));
      EXPECT_FALSE(e.field().empty());
    }
  }
  // Trailing bytes: another layout.
  auto longer = good;
  longer.push_back(0);
  try {
    ros::deserializeGnssMeas(longer, "long");
    FAIL();
  } catch (const ParseError& e) {
    EXPECT_EQ(e.field(), "end of message");
  }
  // A huge count is refused before allocating, naming the array.
  Bytes huge;
  huge.u32(1).u32(2300).f64(1.0).u32(5).u32(0x40000000);
  for (int i = 0; i < 40; ++i) huge.u8(0);
  try {
    ros::deserializeGnssMeas(huge.b, "huge");
    FAIL();
  } catch (const ParseError& e) {
    EXPECT_EQ(e.field(), "meas[0].freqs");
    EXPECT_EQ(e.line(), 20);  // count(4) + time(12) + sat(4)
  }
  // Fewer bytes than one satellite record needs: the meas count itself is refused.
  huge.b.resize(40);
  try {
    ros::deserializeGnssMeas(huge.b, "short");
    FAIL();
  } catch (const ParseError& e) {
    EXPECT_EQ(e.field(), "meas");
    EXPECT_EQ(e.line(), 0);
  }
  // An IMU message is no GnssMeasMsg.
  EXPECT_THROW(ros::deserializeGnssMeas(ros::serialize(ros::ImuMsg{}), "imu as meas"), ParseError);
  EXPECT_THROW(ros::deserializeImu(ros::serialize(ros::GnssEphemMsg{}), "eph as imu"), ParseError);
}

TEST(RosbagConvert, GnssCommSatelliteNumbers) {
  EXPECT_EQ(satFromGnssComm(1), SatId(System::Gps, 1));
  EXPECT_EQ(satFromGnssComm(32), SatId(System::Gps, 32));
  EXPECT_EQ(satFromGnssComm(33), SatId(System::Glonass, 1));
  EXPECT_EQ(satFromGnssComm(59), SatId(System::Glonass, 27));
  EXPECT_EQ(satFromGnssComm(60), SatId(System::Galileo, 1));
  EXPECT_EQ(satFromGnssComm(95), SatId(System::Galileo, 36));
  EXPECT_FALSE(satFromGnssComm(96));  // E37: beyond our Galileo numbers
  EXPECT_EQ(satFromGnssComm(98), SatId(System::BeiDou, 1));
  EXPECT_EQ(satFromGnssComm(160), SatId(System::BeiDou, 63));
  EXPECT_FALSE(satFromGnssComm(0));
  EXPECT_FALSE(satFromGnssComm(161));
  for (std::uint32_t n = 1; n <= 160; ++n)
    if (const auto s = satFromGnssComm(n)) {
      EXPECT_EQ(gnssCommSat(*s), n);
    }
  EXPECT_EQ(gnssCommSat(SatId(System::Qzss, 1)), 0u);
}

TEST(RosbagConvert, BandsFromFrequencies) {
  struct Case {
    System sys;
    double hz;
    char band;
    std::optional<int> k;
  };
  const Case cases[] = {{System::Gps, 1575.42e6, '1', {}},      {System::Gps, 1227.60e6, '2', {}},
                        {System::Gps, 1176.45e6, '5', {}},      {System::Galileo, 1207.14e6, '7', {}},
                        {System::Galileo, 1278.75e6, '6', {}},  {System::BeiDou, 1561.098e6, '2', {}},
                        {System::BeiDou, 1207.14e6, '7', {}},   {System::BeiDou, 1268.52e6, '6', {}},
                        {System::Glonass, 1598.0625e6, '1', -7}, {System::Glonass, 1605.375e6, '1', 6},
                        {System::Glonass, 1242.9375e6, '2', -7}, {System::Glonass, 1248.625e6, '2', 6}};
  for (const Case& c : cases) {
    const auto b = bandFromFrequency(c.sys, c.hz);
    ASSERT_TRUE(b) << c.hz;
    EXPECT_EQ(b->band, c.band) << c.hz;
    EXPECT_EQ(b->glonassChannel, c.k) << c.hz;
  }
  EXPECT_FALSE(bandFromFrequency(System::Gps, 1561.098e6));
  EXPECT_FALSE(bandFromFrequency(System::Glonass, 1602e6 + 7 * 0.5625e6));  // k = 7 does not exist
  EXPECT_FALSE(bandFromFrequency(System::Gps, std::nan("")));
}

TEST(RosbagConvert, ObsMessageToEpochKeepsEveryValue) {
  ros::GnssMeasMsg m;
  m.meas.push_back(sampleObs());
  GlonassChannels ch;
  const ObsEpoch e = toObsEpoch(m, "sample", nullptr, &ch);
  EXPECT_EQ(e.time, GpsTime::fromWeekTow(2320, 345600.25));
  ASSERT_EQ(e.sats.size(), 1u);
  EXPECT_EQ(e.sats[0].sat, SatId(System::Glonass, 2));
  EXPECT_EQ(ch.get(2), -4);
  const SignalObs* g1 = e.sats[0].find(ObsCode('1', 'C'));
  const SignalObs* g2 = e.sats[0].find(ObsCode('2', 'C'));
  ASSERT_TRUE(g1 && g2);
  EXPECT_EQ(g1->pseudorange, 21e6 + 0.123);
  EXPECT_EQ(g2->carrierPhase, 8.6e7 + 0.5);
  EXPECT_EQ(g2->doppler, -960.125);
  EXPECT_EQ(g1->snr, 45.0);
  EXPECT_EQ(g1->ssi, 7);  // RINEX 3.04 5.7: 42-47 dB-Hz -> 7
  EXPECT_EQ(g2->ssi, 6);  // 36-41 dB-Hz -> 6
  EXPECT_TRUE(g2->lossOfLock());
  EXPECT_FALSE(g1->lossOfLock());
  // Inconsistent arrays are named.
  auto bad = m;
  bad.meas[0].cp.pop_back();
  try {
    toObsEpoch(bad, "bad.bag");
    FAIL();
  } catch (const ParseError& err) {
    EXPECT_EQ(err.field(), "meas[0].cp");
  }
  // Satellites of one message must share the time.
  auto two = m;
  two.meas.push_back(sampleObs());
  two.meas[1].time.tow += 1.0;
  EXPECT_THROW(toObsEpoch(two, "two"), ParseError);
}

// Nagoya rover RINEX -> GnssMeasMsg -> bytes -> ObsEpoch: every GPS/GLONASS/Galileo/BeiDou value
// comes back bit-exactly; QZSS satellites are the only ones dropped.
TEST(RosbagConvert, NagoyaRinexThroughMessagesAndBack) {
  const std::string dir = kData + "/gnss/nagoya_static_2024/";
  RinexObsHeader header;
  const auto epochs = readRinexObs(dir + "rover.obs.gz", &header);
  const NavData nav = readRinexNav(dir + "base.nav.gz");
  GlonassChannels channels = header.glonassChannels;
  for (const auto& g : nav.glonass) channels.set(g.sat.prn, g.frequencyChannel);
  ASSERT_EQ(epochs.size(), 301u);
  std::int64_t values = 0, qzss = 0;
  BagConvertStats stats;
  for (const ObsEpoch& in : epochs) {
    const auto bytes = ros::serialize(toGnssMeasMsg(in, channels, &stats));
    GlonassChannels seen;
    const ObsEpoch out = toObsEpoch(ros::deserializeGnssMeas(bytes, "nagoya"), "nagoya", nullptr, &seen);
    EXPECT_EQ(out.time, in.time);
    for (const SatObs& si : in.sats) {
      if (si.sat.system == System::Qzss) {
        ++qzss;
        EXPECT_EQ(out.find(si.sat), nullptr);
        continue;
      }
      const SatObs* so = out.find(si.sat);
      ASSERT_NE(so, nullptr) << si.sat.str();
      for (const SignalObs& s : si.signals) {
        const SignalObs* o = so->find(s.code);
        ASSERT_NE(o, nullptr) << si.sat.str() << " " << s.code.str();
        const auto same = [&](bool hasIn, double vin, bool hasOut, double vout) {
          if (hasIn && vin != 0.0) {
            EXPECT_TRUE(hasOut);
            EXPECT_EQ(std::bit_cast<std::uint64_t>(vout), std::bit_cast<std::uint64_t>(vin));
            ++values;
          } else {
            EXPECT_FALSE(hasOut);
          }
        };
        same(s.hasCode(), s.pseudorange, o->hasCode(), o->pseudorange);
        same(s.hasPhase(), s.carrierPhase, o->hasPhase(), o->carrierPhase);
        same(s.hasDoppler(), s.doppler, o->hasDoppler(), o->doppler);
        same(s.hasSnr(), s.snr, o->hasSnr(), o->snr);
        EXPECT_EQ(o->lli, s.lli & 7);
      }
      if (si.sat.system == System::Glonass) {
        EXPECT_EQ(seen.get(si.sat.prn), channels.get(si.sat.prn));
      }
    }
  }
  EXPECT_GT(values, 301 * 20 * 4);
  EXPECT_EQ(stats.unknownSatellites, qzss);
  EXPECT_GT(qzss, 0);
  EXPECT_EQ(stats.glonassNoChannel, 0);
}

// Nagoya navigation records through the messages: every field the layouts carry survives, and
// the satellite positions and clocks computed from the records are identical.
TEST(RosbagConvert, NagoyaEphemeridesThroughMessagesAndBack) {
  const NavData nav = readRinexNav(kData + "/gnss/nagoya_static_2024/base.nav.gz");
  EphemerisStore before, after;
  int kepler = 0;
  for (const KeplerEphemeris& k : nav.kepler) {
    if (gnssCommSat(k.sat) == 0) continue;
    const auto b = ros::serialize(toGnssEphemMsg(k));
    const KeplerEphemeris r = toKeplerEphemeris(ros::deserializeGnssEphem(b, "eph"), "eph");
    EXPECT_EQ(r.sat, k.sat);
    EXPECT_EQ(r.message, k.message) << k.sat.str();
    EXPECT_EQ(r.toe, k.toe);
    EXPECT_EQ(r.toc, k.toc);
    EXPECT_EQ(r.ttr, k.ttr);
    EXPECT_EQ(r.toeSeconds, k.toeSeconds);
    EXPECT_EQ(r.week, k.week);
    EXPECT_EQ(r.iode, k.iode);
    EXPECT_EQ(r.iodc, k.iodc);
    EXPECT_EQ(r.health, k.health);
    EXPECT_EQ(r.ura, k.ura);
    EXPECT_EQ(r.sqrtA, k.sqrtA);
    for (const auto& [a, c] : {std::pair{r.e, k.e}, {r.i0, k.i0}, {r.omega0, k.omega0}, {r.omega, k.omega},
                               {r.m0, k.m0}, {r.deltaN, k.deltaN}, {r.omegaDot, k.omegaDot}, {r.iDot, k.iDot},
                               {r.cuc, k.cuc}, {r.cus, k.cus}, {r.crc, k.crc}, {r.crs, k.crs}, {r.cic, k.cic},
                               {r.cis, k.cis}, {r.af0, k.af0}, {r.af1, k.af1}, {r.af2, k.af2},
                               {r.tgd[0], k.tgd[0]}, {r.tgd[1], k.tgd[1]}})
      EXPECT_EQ(a, c);
    before.add(k);
    after.add(r);
    ++kepler;
  }
  int glonass = 0;
  for (const GlonassEphemeris& g : nav.glonass) {
    const auto b = ros::serialize(toGnssGloEphemMsg(g));
    const GlonassEphemeris r = toGlonassEphemeris(ros::deserializeGnssGloEphem(b, "glo"), "glo");
    EXPECT_EQ(r.sat, g.sat);
    EXPECT_EQ(r.frequencyChannel, g.frequencyChannel);
    EXPECT_EQ(r.toe, g.toe);
    EXPECT_EQ(r.tof, g.tof);
    EXPECT_EQ(r.position, g.position);
    EXPECT_EQ(r.velocity, g.velocity);
    EXPECT_EQ(r.acceleration, g.acceleration);
    EXPECT_EQ(r.tauN, g.tauN);
    EXPECT_EQ(r.gammaN, g.gammaN);
    EXPECT_EQ(r.health, g.health);
    before.add(g);
    after.add(r);
    ++glonass;
  }
  EXPECT_GT(kepler, 30);
  EXPECT_GT(glonass, 5);
  // Satellite states at an epoch of the rover file agree exactly.
  const GpsTime t = readRinexObs(kData + "/gnss/nagoya_static_2024/rover.obs.gz").at(150).time;
  int states = 0;
  for (SatId s : before.satellites()) {
    const auto a = before.satelliteState(s, t), b = after.satelliteState(s, t);
    ASSERT_EQ(a.has_value(), b.has_value()) << s.str();
    if (!a) continue;
    EXPECT_EQ(a->position, b->position) << s.str();
    EXPECT_EQ(a->clockBias, b->clockBias) << s.str();
    ++states;
  }
  EXPECT_GT(states, 20);
}

TEST(RosbagConvert, ImagesAndImuRoundTrip) {
  cv::Mat gray(5, 7, CV_8UC1);
  for (int r = 0; r < gray.rows; ++r)
    for (int c = 0; c < gray.cols; ++c) gray.at<std::uint8_t>(r, c) = static_cast<std::uint8_t>(r * 31 + c * 7);
  const auto msg = toImageMsg(gray, 1403715273262142976LL, 4);
  EXPECT_EQ(msg.encoding, "mono8");
  EXPECT_EQ(msg.step, 7u);
  EXPECT_EQ(msg.header.stamp.sec, 1403715273u);
  EXPECT_EQ(msg.header.stamp.nsec, 262142976u);
  const cv::Mat back = toMat(ros::deserializeImage(ros::serialize(msg), "img"), "img");
  EXPECT_EQ(cv::norm(back, gray, cv::NORM_INF), 0.0);
  // rgb8 with row padding comes back in BGR order.
  ros::ImageMsg rgb;
  rgb.width = 2;
  rgb.height = 1;
  rgb.encoding = "rgb8";
  rgb.step = 8;
  rgb.data = {10, 20, 30, 40, 50, 60, 0, 0};
  const cv::Mat bgr = toMat(rgb, "rgb");
  EXPECT_EQ(bgr.at<cv::Vec3b>(0, 1), cv::Vec3b(60, 50, 40));
  rgb.data.pop_back();
  EXPECT_THROW(toMat(rgb, "rgb"), ParseError);
  rgb.encoding = "yuv422";
  EXPECT_THROW(toMat(rgb, "rgb"), ParseError);

  vio::ImuSample s;
  s.t_ns = 1403715273262142976LL;
  s.gyro = {0.1, -0.25, 1e-17};
  s.accel = {9.80665, -0.0, 3.0};
  const vio::ImuSample r = toImuSample(ros::deserializeImu(ros::serialize(toImuMsg(s, 1)), "imu"));
  EXPECT_EQ(r.t_ns, s.t_ns);
  EXPECT_EQ(r.gyro, s.gyro);
  EXPECT_EQ(r.accel, s.accel);
}
