// Bag files through Debian's rosbag storage library (see rosbag_file.hpp). Compiled to stubs when
// the library is absent (GVINS_HAVE_ROSBAG undefined).
#include "gvins/fusion/rosbag_file.hpp"

#include <stdexcept>

#include "gvins/base/parse_error.hpp"

#ifdef GVINS_HAVE_ROSBAG
#include <cstring>
#include <filesystem>
#include <map>
#include <set>

#include <rosbag/bag.h>
#include <rosbag/view.h>

namespace {
// A message that is already serialised: rosbag writes its bytes with the type, md5 and definition
// it carries (the ROS message traits are given per instance, as rosbag's own MessageInstance does).
struct RawMessage {
  const gvins::fusion::ros::MessageType* type = nullptr;
  std::string datatype, md5, definition;
  const std::vector<std::uint8_t>* data = nullptr;
};
}  // namespace

namespace ros::message_traits {
template <>
struct MD5Sum<RawMessage> {
  static const char* value(const RawMessage& m) { return m.md5.c_str(); }
  static const char* value() { return "*"; }
};
template <>
struct DataType<RawMessage> {
  static const char* value(const RawMessage& m) { return m.datatype.c_str(); }
  static const char* value() { return "*"; }
};
template <>
struct Definition<RawMessage> {
  static const char* value(const RawMessage& m) { return m.definition.c_str(); }
};
}  // namespace ros::message_traits

namespace ros::serialization {
template <>
struct Serializer<RawMessage> {
  template <typename Stream>
  static void write(Stream& s, const RawMessage& m) {
    if (!m.data->empty()) std::memcpy(s.advance(static_cast<std::uint32_t>(m.data->size())), m.data->data(), m.data->size());
  }
  static std::uint32_t serializedLength(const RawMessage& m) { return static_cast<std::uint32_t>(m.data->size()); }
};
}  // namespace ros::serialization

namespace gvins::fusion {

bool rosbagSupported() { return true; }

namespace {
[[noreturn]] void rethrow(const std::string& path, const std::string& field) {
  try {
    throw;
  } catch (const ParseError&) {
    throw;
  } catch (const std::exception& e) {
    throw ParseError(path, 0, field, std::string("not a readable ROS bag: ") + e.what());
  }
}
}  // namespace

struct BagReader::Impl {
  rosbag::Bag bag;
  std::unique_ptr<rosbag::View> all;
  std::unique_ptr<rosbag::View> view;
  rosbag::View::iterator it;
  bool started = false;
};

BagReader::BagReader(const std::string& path) : path_(path), impl_(std::make_unique<Impl>()) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw ParseError(path, 0, "file", "is a directory, not a bag file");
  if (!std::filesystem::is_regular_file(path, ec)) throw ParseError(path, 0, "file", "no such bag file");
  // The library reads the version line itself; check it first for a clear message.
  {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) throw ParseError(path, 0, "file", "cannot open");
    char line[13] = {};
    const std::size_t n = std::fread(line, 1, 13, f);
    std::fclose(f);
    if (n < 13 || std::memcmp(line, "#ROSBAG V2.0\n", 13) != 0)
      throw ParseError(path, 0, "version line", "does not start with \"#ROSBAG V2.0\" (not a ROS 1 bag of format 2.0)");
  }
  try {
    impl_->bag.open(path, rosbag::bagmode::Read);
    impl_->all = std::make_unique<rosbag::View>(impl_->bag);
  } catch (...) {
    rethrow(path, "bag header/index");
  }
}

BagReader::~BagReader() = default;

std::vector<BagTopic> BagReader::topics() const {
  std::map<std::string, BagTopic> byTopic;
  try {
    for (const rosbag::ConnectionInfo* c : impl_->all->getConnections()) {
      BagTopic& t = byTopic[c->topic];
      t.topic = c->topic;
      t.datatype = c->datatype;
      t.md5sum = c->md5sum;
    }
    for (auto& [name, t] : byTopic) {
      rosbag::View v(impl_->bag, rosbag::TopicQuery(name));
      t.messages = v.size();
    }
  } catch (...) {
    rethrow(path_, "connections");
  }
  std::vector<BagTopic> out;
  for (auto& [name, t] : byTopic) out.push_back(t);
  return out;
}

ros::Time BagReader::startTime() const {
  const ::ros::Time t = impl_->all->size() ? impl_->all->getBeginTime() : ::ros::Time();
  return {t.sec, t.nsec};
}
ros::Time BagReader::endTime() const {
  const ::ros::Time t = impl_->all->size() ? impl_->all->getEndTime() : ::ros::Time();
  return {t.sec, t.nsec};
}
std::uint64_t BagReader::messageCount() const { return impl_->all->size(); }
std::string BagReader::version() const {
  return std::to_string(impl_->bag.getMajorVersion()) + "." + std::to_string(impl_->bag.getMinorVersion());
}

bool BagReader::next(BagMessage& msg, const std::vector<std::string>& topics) {
  try {
    if (!impl_->started) {
      impl_->started = true;
      if (topics.empty())
        impl_->view = std::make_unique<rosbag::View>(impl_->bag);
      else
        impl_->view = std::make_unique<rosbag::View>(impl_->bag, rosbag::TopicQuery(topics));
      impl_->it = impl_->view->begin();
    } else {
      ++impl_->it;
    }
    if (impl_->it == impl_->view->end()) return false;
    const rosbag::MessageInstance& m = *impl_->it;
    msg.topic = m.getTopic();
    msg.datatype = m.getDataType();
    msg.md5sum = m.getMD5Sum();
    msg.time = {m.getTime().sec, m.getTime().nsec};
    msg.data.resize(m.size());
    ::ros::serialization::OStream os(msg.data.data(), static_cast<std::uint32_t>(msg.data.size()));
    m.write(os);
    return true;
  } catch (...) {
    rethrow(path_, "message record");
  }
}

struct BagWriter::Impl {
  rosbag::Bag bag;
  bool open = false;
};

BagWriter::BagWriter(const std::string& path, BagCompression compression)
    : path_(path), impl_(std::make_unique<Impl>()) {
  try {
    impl_->bag.open(path, rosbag::bagmode::Write);
    impl_->bag.setCompression(compression == BagCompression::Bz2   ? rosbag::compression::BZ2
                              : compression == BagCompression::Lz4 ? rosbag::compression::LZ4
                                                                   : rosbag::compression::Uncompressed);
    impl_->open = true;
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot create bag " + path + ": " + e.what());
  }
}

BagWriter::~BagWriter() {
  try {
    close();
  } catch (...) {
  }
}

void BagWriter::write(const std::string& topic, const ros::MessageType& type, const ros::Time& time,
                      const std::vector<std::uint8_t>& data) {
  if (!impl_->open) throw std::logic_error("BagWriter::write after close");
  RawMessage raw;
  raw.datatype = std::string(type.datatype);
  raw.md5 = std::string(type.md5sum);
  raw.definition = std::string(type.definition);
  raw.data = &data;
  try {
    impl_->bag.write(topic, ::ros::Time(time.sec, time.nsec), raw);
  } catch (const std::exception& e) {
    throw std::runtime_error("writing " + topic + " to " + path_ + ": " + e.what());
  }
  ++count_;
}

void BagWriter::close() {
  if (!impl_->open) return;
  impl_->open = false;
  try {
    impl_->bag.close();
  } catch (const std::exception& e) {
    throw std::runtime_error("closing bag " + path_ + ": " + e.what());
  }
}

}  // namespace gvins::fusion

#else  // no rosbag storage library

namespace gvins::fusion {

namespace {
[[noreturn]] void unsupported() {
  throw std::runtime_error(
      "this build has no ROS bag support: install librosbag-storage-dev and configure with -DGVINS_WITH_ROSBAG=ON");
}
}  // namespace

bool rosbagSupported() { return false; }

struct BagReader::Impl {};
BagReader::BagReader(const std::string& path) : path_(path) { unsupported(); }
BagReader::~BagReader() = default;
std::vector<BagTopic> BagReader::topics() const { unsupported(); }
ros::Time BagReader::startTime() const { unsupported(); }
ros::Time BagReader::endTime() const { unsupported(); }
std::uint64_t BagReader::messageCount() const { unsupported(); }
std::string BagReader::version() const { unsupported(); }
bool BagReader::next(BagMessage&, const std::vector<std::string>&) { unsupported(); }

struct BagWriter::Impl {};
BagWriter::BagWriter(const std::string& path, BagCompression) : path_(path) { unsupported(); }
BagWriter::~BagWriter() = default;
void BagWriter::write(const std::string&, const ros::MessageType&, const ros::Time&, const std::vector<std::uint8_t>&) {
  unsupported();
}
void BagWriter::close() {}

}  // namespace gvins::fusion

#endif
