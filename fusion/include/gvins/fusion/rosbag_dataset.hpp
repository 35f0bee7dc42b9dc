// GVINS-style ROS 1 bags as a data source and a data sink.
//
// Topics (the GVINS datasets, github.com/HKUST-Aerial-Robotics/GVINS-Dataset, as written by the
// GVINS u-blox driver): /imu0 (sensor_msgs/Imu), /cam0/image_raw and /cam1/image_raw
// (sensor_msgs/Image; sensor_msgs/CompressedImage is read too), /ublox_driver/range_meas
// (gnss_comm/GnssMeasMsg), /ublox_driver/ephem (gnss_comm/GnssEphemMsg),
// /ublox_driver/glo_ephem (gnss_comm/GnssGloEphemMsg). Other topics are skipped and counted.
// Messages are recognised by their data type; a known data type whose md5 sum differs from ours
// is a different message layout and a ParseError.
//
// Time: IMU and image samples carry their header stamps as integer nanoseconds (for the real
// GVINS bags that is ROS/Unix time; for bags written here from a simulated dataset it is the
// dataset's GPST nanoseconds since 1980-01-06, docs/dataset_format.md). GNSS epochs and
// ephemerides carry GPST from the gnss_comm messages. Items come in bag record-time order.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "gvins/base/observation.hpp"
#include "gvins/ephemeris/glonass_ephemeris.hpp"
#include "gvins/ephemeris/kepler_ephemeris.hpp"
#include "gvins/fusion/rosbag_convert.hpp"
#include "gvins/fusion/rosbag_file.hpp"
#include "gvins/vio/imu_sample.hpp"

namespace gvins::fusion {

struct GvinsBagTopics {
  std::string imu = "/imu0";
  std::vector<std::string> cameras = {"/cam0/image_raw", "/cam1/image_raw"};
  std::string gnssMeas = "/ublox_driver/range_meas";
  std::string ephem = "/ublox_driver/ephem";
  std::string gloEphem = "/ublox_driver/glo_ephem";
};

/// One item of a GVINS bag.
struct GvinsBagItem {
  enum class Kind { Imu, Image, GnssEpoch, Ephemeris, GlonassEphemeris };
  Kind kind = Kind::Imu;
  std::string topic;
  ros::Time recordTime;
  vio::ImuSample imu;                ///< Kind::Imu
  int camera = 0;                    ///< Kind::Image: index into GvinsBagTopics::cameras
  std::int64_t image_t_ns = 0;       ///< Kind::Image: header stamp
  cv::Mat image;                     ///< Kind::Image: as encoded (mono8 -> CV_8UC1, ...)
  ObsEpoch epoch;                    ///< Kind::GnssEpoch
  KeplerEphemeris kepler;            ///< Kind::Ephemeris
  GlonassEphemeris glonass;          ///< Kind::GlonassEphemeris
};

struct GvinsBagReadStats {
  std::int64_t imu = 0, images = 0, gnssEpochs = 0, ephemerides = 0, glonassEphemerides = 0;
  std::map<std::string, std::int64_t> skippedTopics;  ///< topic -> messages skipped
  BagConvertStats convert;
};

class GvinsBagReader {
 public:
  explicit GvinsBagReader(const std::string& path, GvinsBagTopics topics = {});
  /// The next item in record-time order; false at the end. ParseError (file, message offset in
  /// the time-ordered stream, field) for a message that does not decode.
  bool next(GvinsBagItem& item);
  const GvinsBagReadStats& stats() const { return stats_; }
  /// GLONASS channels learned from the measurement frequencies and the GLONASS ephemerides.
  const GlonassChannels& glonassChannels() const { return channels_; }
  BagReader& bag() { return bag_; }

 private:
  BagReader bag_;
  GvinsBagTopics topics_;
  GvinsBagReadStats stats_;
  GlonassChannels channels_;
  BagMessage msg_;
  std::int64_t index_ = 0;
};

/// Writes GVINS-style bags (uncompressed chunks by default).
class GvinsBagWriter {
 public:
  explicit GvinsBagWriter(const std::string& path, GvinsBagTopics topics = {},
                          BagCompression compression = BagCompression::None);
  void writeImu(const vio::ImuSample& s);
  /// CV_8UC1, CV_16UC1 or CV_8UC3 image as sensor_msgs/Image on cameras[camera].
  void writeImage(int camera, std::int64_t t_ns, const cv::Mat& image);
  /// Record time = the epoch's GPST as nanoseconds since 1980-01-06.
  void writeEpoch(const ObsEpoch& epoch, const GlonassChannels& channels, BagConvertStats* stats = nullptr);
  void writeEphemeris(const KeplerEphemeris& eph, std::int64_t record_t_ns);
  void writeEphemeris(const GlonassEphemeris& eph, std::int64_t record_t_ns);
  void close() { bag_.close(); }
  std::uint64_t messagesWritten() const { return bag_.messagesWritten(); }

 private:
  BagWriter bag_;
  GvinsBagTopics topics_;
  std::uint32_t imuSeq_ = 0;
  std::vector<std::uint32_t> imageSeq_;
};

/// GPST instant as integer nanoseconds since 1980-01-06 (the dataset convention).
std::int64_t gpstNanoseconds(const GpsTime& t);

/// Summary of a dataset -> bag or bag -> dataset conversion.
struct BagConversionSummary {
  std::int64_t imu = 0, images = 0, gnssEpochs = 0, ephemerides = 0;
  BagConvertStats convert;
  std::string text() const;
};

struct DatasetToBagOptions {
  /// RINEX observation and navigation files; empty: <dir>/gnss/rover.obs and <dir>/gnss/nav.rnx
  /// when they exist.
  std::string gnssObs, gnssNav;
  BagCompression compression = BagCompression::None;
  GvinsBagTopics topics;
};
/// EuRoC/ASL dataset folder (+ gnss/ RINEX of a gvins-sim dataset) -> GVINS-style bag. Images go
/// out as mono8 (the gray images vio::EurocDataset decodes). Ephemerides are recorded at the
/// first time stamp of the dataset so that a consumer has them before the first epoch.
BagConversionSummary datasetToBag(const std::string& datasetDir, const std::string& bagPath,
                                  const DatasetToBagOptions& options = {});

struct BagToDatasetOptions {
  GvinsBagTopics topics;
  /// Copy imu0/cam*/sensor.yaml from this dataset folder (bags carry no calibration).
  std::string calibrationFrom;
};
/// GVINS bag -> <dir>/mav0/{imu0,cam0,cam1}/data.csv + PNG images (EuRoC layout) and
/// <dir>/gnss/rover.obs (RINEX 3.04) + <dir>/gnss/nav.rnx (RINEX 3.04 nav). Numbers are written in
/// the shortest form that reads back to the same double.
BagConversionSummary bagToDataset(const std::string& bagPath, const std::string& datasetDir,
                                  const BagToDatasetOptions& options = {});

}  // namespace gvins::fusion
