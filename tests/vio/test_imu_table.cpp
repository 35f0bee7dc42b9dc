// IMU tables in other layouts (imu_table.hpp) and RTKLIB time tags (rtklib_time_tag.hpp), on the
// real walk (a u-blox + MEMS IMU rig, tests/data/gnss_imu/walk_0827 and the first 20 s of the
// publisher's conversion in walk_0827_cut): the raw
// log (g, deg/s, a ms counter, with its time-tag file) against the publisher's own conversion of
// the same samples to GPST seconds, g and rad/s (low-pass filtered at 10 Hz).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <string>

#include "gvins/base/parse_error.hpp"
#include "gvins/vio/imu_table.hpp"
#include "gvins/vio/rtklib_time_tag.hpp"

using namespace gvins::vio;
using gvins::ParseError;

namespace {
const std::string kDir = std::string(GVINS_TEST_DATA) + "/gnss_imu/walk_0827_cut";
const std::string kWalk = std::string(GVINS_TEST_DATA) + "/gnss_imu/walk_0827";
constexpr double kG = 9.80665;  // the unit "g"
constexpr double kDeg = M_PI / 180.0;
// 2025-08-28 17:30:40.961 GPST: the publisher's first sample, as its Unix-style GPST count.
constexpr std::int64_t kFirstSfNs = (1756402240LL - 315964800LL) * 1'000'000'000LL + 961'000'000LL;

ImuTableFormat publisherFormat() {
  ImuTableFormat f;
  f.columns = parseImuColumns("t,ax,ay,az,gx,gy,gz,-,-,-,-");
  f.time = ImuTimeKind::GpstUnixSeconds;
  f.accelScale = kG;
  return f;
}

ImuTableFormat rawFormat() {
  ImuTableFormat f;
  f.columns = parseImuColumns("ax,ay,az,gx,gy,gz,t");
  f.time = ImuTimeKind::CounterMs;
  f.accelScale = kG;
  f.gyroScale = kDeg;
  return f;
}

void expectParseError(const std::function<void()>& fn, std::int64_t line, const std::string& field) {
  try {
    fn();
    ADD_FAILURE() << "no ParseError";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.line(), line) << e.what();
    EXPECT_EQ(e.field(), field) << e.what();
  }
}
}  // namespace

TEST(ImuTable, PublisherConversionReadsAsGpst) {
  ImuTableReport rep;
  const auto s = readImuTable(kDir + "/imu_1730_sf_first3000.csv", publisherFormat(), nullptr, &rep);
  ASSERT_EQ(s.size(), 3000u);
  EXPECT_EQ(rep.truncatedSkipped, 0u);
  EXPECT_EQ(s.front().t_ns, kFirstSfNs);
  // The rig stands still for its first second: the specific force is gravity (1.011 g here: a
  // MEMS scale/bias error of about 1 %), the gyro reads its bias only.
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  for (int i = 0; i < 100; ++i) a += s[i].accel / 100.0;
  EXPECT_NEAR(a.norm(), 1.011 * kG, 0.01 * kG);
  EXPECT_GT(a.z(), 0.99 * a.norm());  // z up
  EXPECT_LT(s[0].gyro.norm(), 0.01);
  // The samples come every 6-9 ms (about 150 Hz, not the 100 Hz of the publisher's config).
  EXPECT_NEAR(rep.medianPeriod_s, 0.006, 0.0005);
}

TEST(ImuTable, RawCounterLogPlacedOnGpstByItsTimeTags) {
  const RtklibTimeTag tag = RtklibTimeTag::read(kWalk + "/imu_1730.csv.tag");
  EXPECT_EQ(tag.startGpst_ns(), kFirstSfNs);
  ImuTableReport rep;
  const auto raw = readImuTable(kWalk + "/imu_1730.csv", rawFormat(), &tag, &rep);
  const auto sf = readImuTable(kDir + "/imu_1730_sf_first3000.csv", publisherFormat());
  EXPECT_EQ(rep.truncatedSkipped, 2u);   // the log starts and stops mid-line
  EXPECT_TRUE(rep.tagOffsetsCountCrLf);  // the file lost its CRs, the tags did not
  EXPECT_EQ(rep.untaggedSkipped, 0u);
  ASSERT_EQ(raw.size(), 20455u);         // as many as the publisher's conversion
  // Raw sample k is the publisher's sample k (the cut first line is in neither).
  double worst = 0.0;
  for (std::size_t k = 0; k < sf.size(); ++k) {
    worst = std::max(worst, std::abs(static_cast<double>(raw[k].t_ns - sf[k].t_ns)) * 1e-9);
  }
  // Our clock model (counter drift fitted to the tags over the whole log, offset at the earliest
  // tag) and the publisher's stamps differ by at most 15 ms over the first 20 s.
  std::printf("raw log: %zu samples, drift %.1f ppm, tag latency median %.1f ms max %.1f ms, "
              "largest difference to the publisher's stamps %.1f ms\n",
              raw.size(), rep.counterDrift_ppm, rep.tagLatencyMedian_ms, rep.tagLatencyMax_ms, worst * 1e3);
  EXPECT_LT(worst, 0.015);
  EXPECT_LT(std::abs(rep.counterDrift_ppm), 200.0);
  EXPECT_GT(rep.tagLatencyMedian_ms, 0.0);
  EXPECT_LT(rep.tagLatencyMedian_ms, 50.0);
  // Units and columns: the first second's means agree with the publisher's (filtered) values.
  Eigen::Vector3d da = Eigen::Vector3d::Zero(), dg = Eigen::Vector3d::Zero();
  for (int i = 0; i < 150; ++i) {
    da += (raw[i].accel - sf[i].accel) / 150.0;
    dg += (raw[i].gyro - sf[i].gyro) / 150.0;
  }
  EXPECT_LT(da.norm(), 0.005 * kG);
  EXPECT_LT(dg.norm(), 0.2 * kDeg);
}

TEST(ImuTable, MountingRotationAppliesToBothVectors) {
  ImuTableFormat f;
  f.columns = parseImuColumns("t,gx,gy,gz,ax,ay,az");
  f.rotation = rotationFromRollPitchYaw(180.0, 0.0, -90.0);
  const auto s = parseImuTable("1000,0.1,0,0,0,0,9.8\n2000,0,0,0,0,0,9.8\n", "m.csv", f);
  ASSERT_EQ(s.size(), 2u);
  // Roll 180° turns z down; yaw -90° turns x into -y.
  EXPECT_NEAR(s[0].accel.z(), -9.8, 1e-12);
  EXPECT_NEAR(s[0].gyro.y(), -0.1, 1e-12);
  EXPECT_NEAR(s[0].gyro.x(), 0.0, 1e-12);
}

TEST(ImuTable, MalformedInputNamesLineAndField) {
  const ImuTableFormat f;  // t,gx,gy,gz,ax,ay,az in ns
  expectParseError([&] { parseImuTable("1,0,0,0,0,0,9.8\n2,0,0\n3,0,0,0,0,0,9.8\n", "a.csv", f); }, 2, "line");
  expectParseError([&] { parseImuTable("1,0,0,0,0,0,9.8\n1,0,0,0,0,0,9.8\n", "b.csv", f); }, 2, "t");
  expectParseError([&] { parseImuTable("1,0,0,0,0,0,x\n", "c.csv", f); }, 1, "az");
  expectParseError([&] { parseImuTable("1,900,0,0,0,0,9.8\n", "d.csv", f); }, 1, "gyro");
  ImuTableFormat c = f;
  c.time = ImuTimeKind::CounterMs;
  expectParseError([&] { parseImuTable("1,0,0,0,0,0,9.8\n", "e.csv", c); }, 0, "t");
  ImuTableFormat u = f;
  u.time = ImuTimeKind::GpstUnixSeconds;
  expectParseError([&] { parseImuTable("100.5,0,0,0,0,0,9.8\n", "f.csv", u); }, 1, "t");
  EXPECT_THROW(parseImuColumns("t,ax,ay,az,gx,gy"), std::invalid_argument);
  EXPECT_THROW(parseImuColumns("t,ax,ay,az,gx,gy,gz,ax"), std::invalid_argument);
  EXPECT_THROW(parseImuColumns("t,ax,ay,az,gx,gy,gq"), std::invalid_argument);
  EXPECT_THROW(parseImuTimeKind("utc"), std::invalid_argument);
}

TEST(RtklibTimeTag, MalformedFilesNameTheByteAndField) {
  std::string good(60, '\0');
  good.replace(0, 17, "TIMETAG RTKLIB EX");
  auto put32 = [](std::string& b, std::uint32_t v) { b.append(reinterpret_cast<const char*>(&v), 4); };
  put32(good, 0);
  put32(good, 1756402240u);
  const double frac = 0.5;
  good.append(reinterpret_cast<const char*>(&frac), 8);
  std::string recs = good;
  put32(recs, 10);
  put32(recs, 100);
  put32(recs, 20);
  put32(recs, 50);  // offset goes back
  const RtklibTimeTag ok = RtklibTimeTag::parse(good, "ok.tag");
  EXPECT_EQ(ok.startGpst_ns(), kFirstSfNs - 461'000'000);
  EXPECT_FALSE(ok.writtenBy(1).has_value());
  expectParseError([&] { RtklibTimeTag::parse(good.substr(0, 70), "short.tag"); }, 70, "header");
  expectParseError([&] { RtklibTimeTag::parse("X" + good.substr(1), "magic.tag"); }, 0, "header");
  expectParseError([&] { RtklibTimeTag::parse(good + "abc", "odd.tag"); }, 79, "record");
  expectParseError([&] { RtklibTimeTag::parse(recs, "back.tag"); }, 88, "offset");
}
