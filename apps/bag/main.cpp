// gvins-bag: ROS 1 bags of the GVINS datasets (IMU, camera images, gnss_comm GNSS measurements
// and ephemerides): summary, conversion to a dataset folder and back.
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include "gvins/base/atomic_output_file.hpp"
#include "gvins/base/command_line.hpp"
#include "gvins/base/parse_error.hpp"
#include "gvins/fusion/rosbag_dataset.hpp"

namespace {

const char* kUsage =
    "usage: gvins-bag info BAG\n"
    "       gvins-bag to-dataset BAG -o DIR [--calib-from DATASET]\n"
    "       gvins-bag from-dataset DIR -o BAG [--obs RINEX_OBS] [--nav RINEX_NAV] [--bz2|--lz4]\n"
    "\n"
    "info          topics, types, message counts and time span of a ROS 1 bag (format 2.0), then\n"
    "              the GVINS items it holds (decodes every message: a bad one is reported with\n"
    "              the file, the message and the field).\n"
    "to-dataset    writes DIR/mav0/{imu0,cam0,cam1}/data.csv and PNG images (EuRoC/ASL layout),\n"
    "              DIR/gnss/rover.obs (RINEX 3.04) and DIR/gnss/nav.rnx (RINEX 3.04 navigation).\n"
    "              Bags carry no calibration: --calib-from copies sensor.yaml/body.yaml files\n"
    "              from a dataset folder.\n"
    "from-dataset  reads a EuRoC/ASL dataset folder (as gvins-sim writes it) and its gnss/rover.obs\n"
    "              and gnss/nav.rnx (or --obs/--nav) and writes a GVINS-style bag: /imu0,\n"
    "              /cam0/image_raw, /cam1/image_raw (mono8), /ublox_driver/range_meas,\n"
    "              /ublox_driver/ephem, /ublox_driver/glo_ephem. Chunks uncompressed unless\n"
    "              --bz2 or --lz4.\n"
    "\n"
    "Exit status: 0 success, 1 bad input file or write error, 2 bad arguments.\n";

[[noreturn]] int usageError(const std::string& msg) { gvins::usageError("gvins-bag", msg); }

std::string timeText(const gvins::fusion::ros::Time& t) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%u.%09u", t.sec, t.nsec);
  return buf;
}

int info(const std::string& path) {
  using namespace gvins::fusion;
  GvinsBagReader reader(path);
  BagReader& bag = reader.bag();
  std::printf("bag        %s\nversion    %s\nmessages   %llu\nstart      %s\nend        %s\n", path.c_str(),
              bag.version().c_str(), static_cast<unsigned long long>(bag.messageCount()),
              timeText(bag.startTime()).c_str(), timeText(bag.endTime()).c_str());
  std::printf("\n%-32s %-30s %10s\n", "topic", "type", "messages");
  for (const BagTopic& t : bag.topics())
    std::printf("%-32s %-30s %10llu\n", t.topic.c_str(), t.datatype.c_str(), static_cast<unsigned long long>(t.messages));
  GvinsBagItem item;
  gvins::GpsTime firstEpoch, lastEpoch;
  while (reader.next(item)) {
    if (item.kind == GvinsBagItem::Kind::GnssEpoch) {
      if (reader.stats().gnssEpochs == 1) firstEpoch = item.epoch.time;
      lastEpoch = item.epoch.time;
    }
  }
  const GvinsBagReadStats& s = reader.stats();
  std::printf("\nGVINS items\n  IMU samples          %lld\n  images               %lld\n  GNSS epochs          %lld\n",
              static_cast<long long>(s.imu), static_cast<long long>(s.images), static_cast<long long>(s.gnssEpochs));
  if (s.gnssEpochs)
    std::printf("    first / last       %s / %s GPST\n", firstEpoch.toString(1).c_str(), lastEpoch.toString(1).c_str());
  std::printf("  ephemerides          %lld (+ %lld GLONASS)\n", static_cast<long long>(s.ephemerides),
              static_cast<long long>(s.glonassEphemerides));
  std::printf("  skipped satellites   %lld\n  skipped signals      %lld\n",
              static_cast<long long>(s.convert.unknownSatellites),
              static_cast<long long>(s.convert.unknownSignals + s.convert.duplicateSignals));
  for (const auto& [topic, n] : s.skippedTopics)
    std::printf("  skipped topic        %s (%lld)\n", topic.c_str(), static_cast<long long>(n));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) return usageError("missing command");
  const std::string cmd = argv[1];
  if (cmd == "-h" || cmd == "--help") {
    std::fputs(kUsage, stdout);
    return 0;
  }
  std::vector<std::string> positional;
  std::string out, calib, obs, nav;
  gvins::fusion::BagCompression compression = gvins::fusion::BagCompression::None;
  gvins::CommandLine cl("gvins-bag", kUsage, argc, argv, 2);
  while (cl.next()) {
    if (cl.is("-o")) out = cl.value();
    else if (cl.is("--calib-from")) calib = cl.value();
    else if (cl.is("--obs")) obs = cl.value();
    else if (cl.is("--nav")) nav = cl.value();
    else if (cl.is("--bz2")) compression = gvins::fusion::BagCompression::Bz2;
    else if (cl.is("--lz4")) compression = gvins::fusion::BagCompression::Lz4;
    else positional.push_back(cl.operand());
  }
  if (!gvins::fusion::rosbagSupported()) {
    std::fprintf(stderr, "gvins-bag: this build has no ROS bag support (librosbag-storage-dev, GVINS_WITH_ROSBAG)\n");
    return 1;
  }
  try {
    if (cmd == "info") {
      if (positional.size() != 1) return usageError("info needs one BAG");
      return info(positional[0]);
    }
    if (cmd == "to-dataset") {
      if (positional.size() != 1 || out.empty()) return usageError("to-dataset needs BAG and -o DIR");
      if (!calib.empty()) {
        // A folder to copy from that holds nothing to copy is a mistake, not a dataset without calibration.
        namespace fs = std::filesystem;
        std::error_code ec;
        const fs::path from = fs::exists(fs::path(calib) / "mav0", ec) ? fs::path(calib) / "mav0" : fs::path(calib);
        bool any = fs::exists(from / "body.yaml", ec);
        for (const char* sensor : {"imu0", "cam0", "cam1"}) any = any || fs::exists(from / sensor / "sensor.yaml", ec);
        if (!fs::is_directory(calib, ec)) {
          std::fprintf(stderr, "gvins-bag: --calib-from %s: no such dataset folder\n", calib.c_str());
          return 1;
        }
        if (!any) {
          std::fprintf(stderr, "gvins-bag: --calib-from %s: no imu0/cam0/cam1 sensor.yaml or body.yaml to copy\n",
                       calib.c_str());
          return 1;
        }
      }
      gvins::fusion::BagToDatasetOptions o;
      o.calibrationFrom = calib;
      const auto s = gvins::fusion::bagToDataset(positional[0], out, o);
      std::printf("gvins-bag to-dataset %s -> %s\n%s", positional[0].c_str(), out.c_str(), s.text().c_str());
      return 0;
    }
    if (cmd == "from-dataset") {
      if (positional.size() != 1 || out.empty()) return usageError("from-dataset needs DIR and -o BAG");
      gvins::fusion::DatasetToBagOptions o;
      o.gnssObs = obs;
      o.gnssNav = nav;
      o.compression = compression;
      // Written under a temporary name: a failed conversion leaves no bag that reads as valid.
      gvins::AtomicOutputFile bagFile(out);
      const auto s = gvins::fusion::datasetToBag(positional[0], bagFile.tempPath(), o);
      bagFile.commit();
      std::printf("gvins-bag from-dataset %s -> %s\n%s", positional[0].c_str(), out.c_str(), s.text().c_str());
      return 0;
    }
  } catch (const gvins::ParseError& e) {
    std::fprintf(stderr, "gvins-bag: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gvins-bag: %s\n", e.what());
    return 1;
  }
  return usageError("unknown command " + cmd);
}
