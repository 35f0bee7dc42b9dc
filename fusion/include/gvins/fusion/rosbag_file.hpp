// ROS 1 bag files (format 2.0) through Debian's rosbag storage library (librosbag-storage-dev,
// ROS 1.15), an optional build feature: with -DGVINS_WITH_ROSBAG=ON and the library installed,
// BagReader/BagWriter work; otherwise rosbagSupported() is false and their constructors throw
// std::runtime_error saying so. Messages are handled as raw serialised bytes; the GVINS message
// layouts are decoded by rosbag_messages.hpp (no generated ROS message headers are needed).
// Every error of the library (bad header, truncated file, unindexed bag, bad chunk) is turned into
// a gvins::ParseError naming the file and, where the library says it, the offset.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "gvins/fusion/rosbag_messages.hpp"

namespace gvins::fusion {

/// Whether this build can read and write bag files.
bool rosbagSupported();

/// One message of a bag as stored.
struct BagMessage {
  std::string topic;
  std::string datatype;
  std::string md5sum;
  ros::Time time;  ///< record time (receipt time when recorded)
  std::vector<std::uint8_t> data;
};

/// One topic (connection) of a bag.
struct BagTopic {
  std::string topic, datatype, md5sum;
  std::uint64_t messages = 0;
};

class BagReader {
 public:
  /// Opens the bag and reads its index; ParseError for anything that is not a readable bag.
  explicit BagReader(const std::string& path);
  ~BagReader();
  BagReader(const BagReader&) = delete;
  BagReader& operator=(const BagReader&) = delete;

  const std::string& path() const { return path_; }
  std::vector<BagTopic> topics() const;
  ros::Time startTime() const;
  ros::Time endTime() const;
  std::uint64_t messageCount() const;
  /// Version string of the file ("2.0").
  std::string version() const;

  /// Next message over the given topics (all when empty) in record-time order; false at the end.
  /// The topic set is fixed by the first call.
  bool next(BagMessage& msg, const std::vector<std::string>& topics = {});

 private:
  struct Impl;
  std::string path_;
  std::unique_ptr<Impl> impl_;
};

enum class BagCompression { None, Bz2, Lz4 };

class BagWriter {
 public:
  explicit BagWriter(const std::string& path, BagCompression compression = BagCompression::None);
  ~BagWriter();  ///< closes (errors are swallowed: call close() to see them)
  BagWriter(const BagWriter&) = delete;
  BagWriter& operator=(const BagWriter&) = delete;

  /// Writes one serialised message of the given type. Record times must be >= ROS time 0.000001.
  void write(const std::string& topic, const ros::MessageType& type, const ros::Time& time,
             const std::vector<std::uint8_t>& data);
  std::uint64_t messagesWritten() const { return count_; }
  void close();

 private:
  struct Impl;
  std::string path_;
  std::unique_ptr<Impl> impl_;
  std::uint64_t count_ = 0;
};

}  // namespace gvins::fusion
