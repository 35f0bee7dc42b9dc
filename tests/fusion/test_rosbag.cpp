// ROS 1 bag files: a GVINS-style bag written from a dataset folder (the bundled EuRoC V1_01 clip
// in the layout gvins-sim writes, with the bundled Nagoya rover RINEX and navigation file as its
// gnss/ part) reads back bit-exactly; bag -> dataset -> readers gives the original values; the
// gvins-bag tool; malformed bags give ParseErrors naming file and field.
// Truth: the source files themselves (EuRoC CSV/PNG read by vio::EurocDataset, RINEX read by the
// base/ephemeris readers), independently of the bag code.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <cstring>

#include <sys/wait.h>
#include <unistd.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "gvins/base/parse_error.hpp"
#include "gvins/base/rinex_obs_reader.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/fusion/rosbag_dataset.hpp"
#include "gvins/vio/euroc_dataset.hpp"

using namespace gvins;
using namespace gvins::fusion;
namespace fs = std::filesystem;

namespace {

const std::string kData = GVINS_TEST_DATA;
const std::string kEuroc = kData + "/euroc/v101_static_stereo";
const std::string kObs = kData + "/gnss/nagoya_static_2024/rover.obs.gz";
const std::string kNav = kData + "/gnss/nagoya_static_2024/base.nav.gz";

fs::path tempDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("gvins_test_rosbag_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::vector<char> readAll(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), {}};
}
void writeAll(const fs::path& p, const std::vector<char>& b) {
  std::ofstream f(p, std::ios::binary);
  f.write(b.data(), static_cast<std::streamsize>(b.size()));
}

bool sameValue(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Compares an epoch read back against the RINEX original: GPS/GLONASS/Galileo/BeiDou signals with
// every non-zero value identical; returns the number of values compared.
std::int64_t compareEpoch(const ObsEpoch& in, const ObsEpoch& out) {
  std::int64_t n = 0;
  EXPECT_EQ(out.time, in.time);
  for (const SatObs& si : in.sats) {
    if (gnssCommSat(si.sat) == 0) continue;
    const SatObs* so = out.find(si.sat);
    if (!so) {
      ADD_FAILURE() << si.sat.str() << " missing at " << in.time.toString();
      continue;
    }
    for (const SignalObs& s : si.signals) {
      const SignalObs* o = so->find(s.code);
      if (!o) {
        ADD_FAILURE() << si.sat.str() << " " << s.code.str();
        continue;
      }
      if (s.hasCode() && s.pseudorange != 0.0) {
        EXPECT_TRUE(o->hasCode() && sameValue(o->pseudorange, s.pseudorange));
        ++n;
      }
      if (s.hasPhase() && s.carrierPhase != 0.0) {
        EXPECT_TRUE(o->hasPhase() && sameValue(o->carrierPhase, s.carrierPhase));
        ++n;
      }
      if (s.hasDoppler() && s.doppler != 0.0) {
        EXPECT_TRUE(o->hasDoppler() && sameValue(o->doppler, s.doppler));
        ++n;
      }
      if (s.hasSnr() && s.snr != 0.0) {
        EXPECT_TRUE(o->hasSnr() && sameValue(o->snr, s.snr));
        ++n;
      }
      EXPECT_EQ(o->lli, s.lli & 7);
    }
  }
  return n;
}

class RosbagFile : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!rosbagSupported()) GTEST_SKIP() << "built without librosbag-storage-dev";
  }
};

}  // namespace

TEST_F(RosbagFile, DatasetToBagReadsBackBitExactly) {
  const fs::path dir = tempDir("write");
  const std::string bag = (dir / "v101_nagoya.bag").string();
  DatasetToBagOptions opt;
  opt.gnssObs = kObs;
  opt.gnssNav = kNav;
  const BagConversionSummary sum = datasetToBag(kEuroc, bag, opt);

  vio::EurocDataset data(kEuroc);
  const auto epochs = readRinexObs(kObs);
  const NavData nav = readRinexNav(kNav);
  EXPECT_EQ(sum.imu, static_cast<std::int64_t>(data.imu().size()));
  EXPECT_EQ(sum.images, static_cast<std::int64_t>(data.cameraEntries(0).size() + data.cameraEntries(1).size()));
  EXPECT_EQ(sum.gnssEpochs, 301);

  GvinsBagReader reader(bag);
  EXPECT_EQ(reader.bag().version(), "2.0");
  std::size_t imu = 0, img[2] = {0, 0}, ep = 0, keph = 0, geph = 0;
  std::int64_t values = 0;
  std::int64_t lastRecord = -1;
  GvinsBagItem item;
  while (reader.next(item)) {
    const std::int64_t rec = toNanoseconds(item.recordTime);
    EXPECT_GE(rec, lastRecord);  // time-ordered
    lastRecord = rec;
    switch (item.kind) {
      case GvinsBagItem::Kind::Imu: {
        ASSERT_LT(imu, data.imu().size());
        const vio::ImuSample& s = data.imu()[imu++];
        EXPECT_EQ(item.imu.t_ns, s.t_ns);
        for (int i = 0; i < 3; ++i) {
          EXPECT_TRUE(sameValue(item.imu.gyro[i], s.gyro[i]));
          EXPECT_TRUE(sameValue(item.imu.accel[i], s.accel[i]));
        }
        break;
      }
      case GvinsBagItem::Kind::Image: {
        const int c = item.camera;
        ASSERT_LT(img[c], data.cameraEntries(c).size());
        EXPECT_EQ(item.image_t_ns, data.cameraEntries(c)[img[c]].t_ns);
        const cv::Mat ref = data.loadImage(c, img[c]++);
        ASSERT_EQ(item.image.type(), CV_8UC1);
        ASSERT_EQ(item.image.size(), ref.size());
        EXPECT_EQ(cv::norm(item.image, ref, cv::NORM_INF), 0.0);
        break;
      }
      case GvinsBagItem::Kind::GnssEpoch:
        ASSERT_LT(ep, epochs.size());
        values += compareEpoch(epochs[ep++], item.epoch);
        break;
      case GvinsBagItem::Kind::Ephemeris: ++keph; break;
      case GvinsBagItem::Kind::GlonassEphemeris: ++geph; break;
    }
  }
  EXPECT_EQ(imu, data.imu().size());
  EXPECT_EQ(img[0], data.cameraEntries(0).size());
  EXPECT_EQ(img[1], data.cameraEntries(1).size());
  EXPECT_EQ(ep, 301u);
  EXPECT_GT(values, 301 * 60);
  std::size_t representable = 0;
  for (const auto& k : nav.kepler) representable += gnssCommSat(k.sat) != 0;
  EXPECT_EQ(keph, representable);
  EXPECT_EQ(geph, nav.glonass.size());
  // Topics as in the GVINS datasets.
  std::map<std::string, std::string> types;
  for (const BagTopic& t : reader.bag().topics()) types[t.topic] = t.datatype;
  EXPECT_EQ(types["/imu0"], "sensor_msgs/Imu");
  EXPECT_EQ(types["/cam0/image_raw"], "sensor_msgs/Image");
  EXPECT_EQ(types["/ublox_driver/range_meas"], "gnss_comm/GnssMeasMsg");
  EXPECT_EQ(types["/ublox_driver/ephem"], "gnss_comm/GnssEphemMsg");
  EXPECT_EQ(types["/ublox_driver/glo_ephem"], "gnss_comm/GnssGloEphemMsg");
  fs::remove_all(dir);
}

TEST_F(RosbagFile, CompressedChunksReadBackTheSame) {
  const fs::path dir = tempDir("compressed");
  for (BagCompression c : {BagCompression::Bz2, BagCompression::Lz4}) {
    const std::string bag = (dir / "c.bag").string();
    {
      GvinsBagWriter w(bag, {}, c);
      vio::ImuSample s;
      for (int i = 0; i < 500; ++i) {
        s.t_ns = 1'400'000'000'000'000'000LL + i * 5'000'000LL;
        s.gyro = {0.001 * i, -0.5, 1.0 / (i + 1)};
        s.accel = {0.0, 9.81, -1.0 * i};
        w.writeImu(s);
      }
      w.close();
    }
    GvinsBagReader r(bag);
    GvinsBagItem item;
    int i = 0;
    while (r.next(item)) {
      ASSERT_EQ(item.kind, GvinsBagItem::Kind::Imu);
      EXPECT_EQ(item.imu.t_ns, 1'400'000'000'000'000'000LL + i * 5'000'000LL);
      EXPECT_EQ(item.imu.gyro[2], 1.0 / (i + 1));
      EXPECT_EQ(item.imu.accel[2], -1.0 * i);
      ++i;
    }
    EXPECT_EQ(i, 500);
  }
  fs::remove_all(dir);
}

TEST_F(RosbagFile, BagToDatasetAndBack) {
  const fs::path dir = tempDir("todataset");
  const std::string bag = (dir / "a.bag").string();
  DatasetToBagOptions opt;
  opt.gnssObs = kObs;
  opt.gnssNav = kNav;
  datasetToBag(kEuroc, bag, opt);
  BagToDatasetOptions back;
  back.calibrationFrom = kEuroc;
  const fs::path out = dir / "dataset";
  const BagConversionSummary sum = bagToDataset(bag, out.string(), back);
  EXPECT_EQ(sum.gnssEpochs, 301);

  // The written folder is a EuRoC dataset with the original IMU values and images.
  vio::EurocDataset orig(kEuroc), copy(out.string());
  ASSERT_EQ(copy.imu().size(), orig.imu().size());
  for (std::size_t i = 0; i < orig.imu().size(); ++i) {
    EXPECT_EQ(copy.imu()[i].t_ns, orig.imu()[i].t_ns);
    EXPECT_EQ(copy.imu()[i].gyro, orig.imu()[i].gyro);
    EXPECT_EQ(copy.imu()[i].accel, orig.imu()[i].accel);
  }
  for (int c = 0; c < 2; ++c) {
    ASSERT_EQ(copy.cameraEntries(c).size(), orig.cameraEntries(c).size());
    for (std::size_t i = 0; i < orig.cameraEntries(c).size(); ++i) {
      EXPECT_EQ(copy.cameraEntries(c)[i].t_ns, orig.cameraEntries(c)[i].t_ns);
      EXPECT_EQ(cv::norm(copy.loadImage(c, i), orig.loadImage(c, i), cv::NORM_INF), 0.0);
    }
  }
  // RINEX written from the bag holds the original values (RINEX resolution equals the source's).
  const auto in = readRinexObs(kObs);
  const auto rt = readRinexObs((out / "gnss" / "rover.obs").string());
  ASSERT_EQ(rt.size(), in.size());
  std::int64_t values = 0;
  for (std::size_t i = 0; i < in.size(); ++i) values += compareEpoch(in[i], rt[i]);
  EXPECT_GT(values, 301 * 60);
  const NavData nav = readRinexNav(kNav), nav2 = readRinexNav((out / "gnss" / "nav.rnx").string());
  EXPECT_EQ(nav2.glonass.size(), nav.glonass.size());
  std::size_t matched = 0;
  for (const KeplerEphemeris& k : nav.kepler) {
    for (const KeplerEphemeris& k2 : nav2.kepler) {
      if (k2.sat == k.sat && k2.message == k.message && k2.toe == k.toe && k2.iode == k.iode) {
        EXPECT_EQ(k2.sqrtA, k.sqrtA) << k.sat.str();
        EXPECT_EQ(k2.m0, k.m0) << k.sat.str();
        EXPECT_EQ(k2.af0, k.af0) << k.sat.str();
        ++matched;
        break;
      }
    }
  }
  std::size_t representable = 0;
  for (const auto& k : nav.kepler) representable += gnssCommSat(k.sat) != 0;
  EXPECT_EQ(matched, representable);
  fs::remove_all(dir);
}

TEST_F(RosbagFile, MalformedBagsGiveClearErrors) {
  const fs::path dir = tempDir("malformed");
  const fs::path good = dir / "good.bag";
  {
    GvinsBagWriter w(good.string());
    vio::ImuSample s;
    for (int i = 0; i < 200; ++i) {
      s.t_ns = 1'000'000'000LL * 1400000000 + i * 5'000'000LL;
      w.writeImu(s);
    }
    w.close();
  }
  const auto bytes = readAll(good);
  ASSERT_GT(bytes.size(), 1000u);
  // Missing file.
  EXPECT_THROW(GvinsBagReader((dir / "none.bag").string()), ParseError);
  // Bad version line.
  {
    auto b = bytes;
    b[9] = '1';  // "#ROSBAG V1.0"
    writeAll(dir / "v1.bag", b);
    try {
      GvinsBagReader r((dir / "v1.bag").string());
      FAIL();
    } catch (const ParseError& e) {
      EXPECT_EQ(e.file(), (dir / "v1.bag").string());
      EXPECT_EQ(e.field(), "version line");
    }
    writeAll(dir / "text.bag", std::vector<char>{'h', 'e', 'l', 'l', 'o'});
    EXPECT_THROW(GvinsBagReader((dir / "text.bag").string()), ParseError);
  }
  // Truncated at several places: an error naming the file, never a crash or a hang.
  for (std::size_t n : {std::size_t{13}, std::size_t{100}, bytes.size() / 2, bytes.size() - 20}) {
    std::vector<char> b(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(n));
    const fs::path p = dir / ("cut" + std::to_string(n) + ".bag");
    writeAll(p, b);
    try {
      GvinsBagReader r(p.string());
      GvinsBagItem item;
      while (r.next(item)) {
      }
      ADD_FAILURE() << "truncated to " << n << " bytes was accepted";
    } catch (const ParseError& e) {
      EXPECT_EQ(e.file(), p.string()) << e.what();
    }
  }
  // A known type with a different layout (md5) and a message whose bytes are another layout.
  {
    const fs::path p = dir / "layout.bag";
    {
      BagWriter w(p.string());
      const ros::MessageType& meas = ros::gnssMeasType();
      const ros::MessageType other{meas.datatype, "0123456789abcdef0123456789abcdef", meas.definition};
      w.write("/other/range_meas", other, {1400000000, 0}, ros::serialize(ros::GnssMeasMsg{}));
      w.close();
    }
    GvinsBagReader r(p.string());
    GvinsBagItem item;
    try {
      r.next(item);
      FAIL();
    } catch (const ParseError& e) {
      EXPECT_EQ(e.field(), "md5sum");
      EXPECT_NE(std::string(e.what()).find("/other/range_meas"), std::string::npos) << e.what();
    }
  }
  {
    const fs::path p = dir / "bytes.bag";
    {
      BagWriter w(p.string());
      vio::ImuSample s;
      s.t_ns = 1'400'000'000'000'000'000LL;
      w.write("/ublox_driver/range_meas", ros::gnssMeasType(), {1400000000, 0}, ros::serialize(toImuMsg(s, 0)));
      w.close();
    }
    GvinsBagReader r(p.string());
    GvinsBagItem item;
    EXPECT_THROW(r.next(item), ParseError);
  }
  fs::remove_all(dir);
}

TEST_F(RosbagFile, GvinsBagTool) {
  const fs::path dir = tempDir("cli");
  const std::string bin = std::string(GVINS_BIN_DIR) + "/gvins-bag";
  const std::string bag = (dir / "t.bag").string();
  const auto run = [&](const std::string& args, const fs::path& out) {
    const std::string cmd = bin + " " + args + " > " + out.string() + " 2>&1";
    const int rc = std::system(cmd.c_str());
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  };
  ASSERT_EQ(run("from-dataset " + kEuroc + " -o " + bag + " --obs " + kObs + " --nav " + kNav + " --lz4",
                dir / "from.txt"),
            0);
  ASSERT_EQ(run("info " + bag, dir / "info.txt"), 0);
  std::ifstream f(dir / "info.txt");
  const std::string text((std::istreambuf_iterator<char>(f)), {});
  EXPECT_NE(text.find("gnss_comm/GnssMeasMsg"), std::string::npos) << text;
  EXPECT_NE(text.find("GNSS epochs          301"), std::string::npos) << text;
  ASSERT_EQ(run("to-dataset " + bag + " -o " + (dir / "ds").string() + " --calib-from " + kEuroc, dir / "to.txt"), 0);
  EXPECT_TRUE(fs::exists(dir / "ds" / "gnss" / "rover.obs"));
  EXPECT_EQ(readRinexObs((dir / "ds" / "gnss" / "rover.obs").string()).size(), 301u);
  vio::EurocDataset copy((dir / "ds").string());
  EXPECT_EQ(copy.imu().size(), vio::EurocDataset(kEuroc).imu().size());
  // Errors: bad file 1, bad arguments 2.
  writeAll(dir / "bad.bag", std::vector<char>(100, 'x'));
  EXPECT_EQ(run("info " + (dir / "bad.bag").string(), dir / "bad.txt"), 1);
  std::ifstream fb(dir / "bad.txt");
  const std::string bad((std::istreambuf_iterator<char>(fb)), {});
  EXPECT_NE(bad.find("bad.bag"), std::string::npos) << bad;
  EXPECT_EQ(run("to-dataset " + bag, dir / "args.txt"), 2);
  EXPECT_EQ(run("frobnicate", dir / "args.txt"), 2);
  fs::remove_all(dir);
}

TEST_F(RosbagFile, CompressedImagesAndForeignTopics) {
  const fs::path dir = tempDir("compressed_image");
  const std::string bag = (dir / "c.bag").string();
  vio::EurocDataset data(kEuroc);
  const cv::Mat ref = data.loadImage(0, 3);
  std::vector<std::uint8_t> png;
  ASSERT_TRUE(cv::imencode(".png", ref, png));
  {
    BagWriter w(bag);
    ros::CompressedImageMsg m;
    m.header.stamp = toRosTime(data.cameraEntries(0)[3].t_ns);
    m.format = "mono8; png compressed";
    m.data = png;
    w.write("/cam0/image_raw/compressed", ros::compressedImageType(), m.header.stamp, ros::serialize(m));
    // A topic the reader does not know (e.g. the u-blox driver's time pulse) is skipped and counted.
    w.write("/ublox_driver/time_pulse_info", ros::MessageType{"gnss_comm/GnssTimePulseInfoMsg", "*", ""},
            m.header.stamp, std::vector<std::uint8_t>(13, 0));
    m.data.resize(m.data.size() / 2);  // a broken PNG
    m.header.stamp.sec += 1;
    w.write("/cam0/image_raw/compressed", ros::compressedImageType(), m.header.stamp, ros::serialize(m));
    w.close();
  }
  GvinsBagReader r(bag);
  GvinsBagItem item;
  ASSERT_TRUE(r.next(item));
  EXPECT_EQ(item.kind, GvinsBagItem::Kind::Image);
  EXPECT_EQ(item.camera, 0);
  EXPECT_EQ(item.image_t_ns, data.cameraEntries(0)[3].t_ns);
  EXPECT_EQ(cv::norm(item.image, ref, cv::NORM_INF), 0.0);
  EXPECT_THROW(r.next(item), ParseError);  // the broken PNG, after skipping the time pulse
  EXPECT_EQ(r.stats().skippedTopics.at("/ublox_driver/time_pulse_info"), 1);
  fs::remove_all(dir);
}
