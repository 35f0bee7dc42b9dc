// GVINS-style bags as a data source and sink; see rosbag_dataset.hpp.
#include "gvins/fusion/rosbag_dataset.hpp"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <opencv2/imgcodecs.hpp>

#include "gvins/base/parse_error.hpp"
#include "gvins/base/rinex_obs_reader.hpp"
#include "gvins/base/rinex_obs_writer.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/vio/euroc_dataset.hpp"

namespace gvins::fusion {
namespace fs = std::filesystem;

namespace {

void checkType(const BagMessage& m, const ros::MessageType& t, const std::string& source) {
  if (m.md5sum != t.md5sum && m.md5sum != "*")
    throw ParseError(source, 0, "md5sum",
                     "type " + m.datatype + " has md5 " + m.md5sum + ", the known layout has " +
                         std::string(t.md5sum) + " (a different message layout)");
}

}  // namespace

std::int64_t gpstNanoseconds(const GpsTime& t) {
  const double fracNs = std::round(t.fraction() * 1e9);
  return t.wholeSeconds() * 1'000'000'000 + static_cast<std::int64_t>(fracNs);
}

// ---- reader ----------------------------------------------------------------------------------

GvinsBagReader::GvinsBagReader(const std::string& path, GvinsBagTopics topics)
    : bag_(path), topics_(std::move(topics)) {}

bool GvinsBagReader::next(GvinsBagItem& item) {
  while (bag_.next(msg_)) {
    const std::string source = bag_.path() + ": message " + std::to_string(index_) + " (" + msg_.topic + ", " +
                               msg_.datatype + ")";
    ++index_;
    item.topic = msg_.topic;
    item.recordTime = msg_.time;
    const std::string& type = msg_.datatype;
    if (type == ros::imuType().datatype && msg_.topic == topics_.imu) {
      checkType(msg_, ros::imuType(), source);
      item.kind = GvinsBagItem::Kind::Imu;
      item.imu = toImuSample(ros::deserializeImu(msg_.data, source));
      ++stats_.imu;
      return true;
    }
    if (type == ros::imageType().datatype || type == ros::compressedImageType().datatype) {
      int cam = -1;
      for (std::size_t i = 0; i < topics_.cameras.size(); ++i)
        if (topics_.cameras[i] == msg_.topic) cam = static_cast<int>(i);
      // GVINS-style compressed topics: "<camera topic>/compressed".
      for (std::size_t i = 0; i < topics_.cameras.size() && cam < 0; ++i)
        if (topics_.cameras[i] + "/compressed" == msg_.topic) cam = static_cast<int>(i);
      if (cam >= 0) {
        item.kind = GvinsBagItem::Kind::Image;
        item.camera = cam;
        if (type == ros::imageType().datatype) {
          checkType(msg_, ros::imageType(), source);
          const ros::ImageMsg im = ros::deserializeImage(msg_.data, source);
          item.image_t_ns = toNanoseconds(im.header.stamp);
          item.image = toMat(im, source);
        } else {
          checkType(msg_, ros::compressedImageType(), source);
          const ros::CompressedImageMsg im = ros::deserializeCompressedImage(msg_.data, source);
          item.image_t_ns = toNanoseconds(im.header.stamp);
          item.image = toMat(im, source);
        }
        ++stats_.images;
        return true;
      }
    }
    if (type == ros::gnssMeasType().datatype) {
      checkType(msg_, ros::gnssMeasType(), source);
      item.kind = GvinsBagItem::Kind::GnssEpoch;
      item.epoch = toObsEpoch(ros::deserializeGnssMeas(msg_.data, source), source, &stats_.convert, &channels_);
      if (item.epoch.sats.empty() && item.epoch.time == GpsTime()) {  // an empty message has no time
        stats_.skippedTopics[msg_.topic + " (empty)"]++;
        continue;
      }
      ++stats_.gnssEpochs;
      return true;
    }
    if (type == ros::gnssEphemType().datatype) {
      checkType(msg_, ros::gnssEphemType(), source);
      item.kind = GvinsBagItem::Kind::Ephemeris;
      item.kepler = toKeplerEphemeris(ros::deserializeGnssEphem(msg_.data, source), source);
      ++stats_.ephemerides;
      return true;
    }
    if (type == ros::gnssGloEphemType().datatype) {
      checkType(msg_, ros::gnssGloEphemType(), source);
      item.kind = GvinsBagItem::Kind::GlonassEphemeris;
      item.glonass = toGlonassEphemeris(ros::deserializeGnssGloEphem(msg_.data, source), source);
      channels_.set(item.glonass.sat.prn, item.glonass.frequencyChannel);
      ++stats_.glonassEphemerides;
      return true;
    }
    stats_.skippedTopics[msg_.topic]++;
  }
  return false;
}

// ---- writer ----------------------------------------------------------------------------------

GvinsBagWriter::GvinsBagWriter(const std::string& path, GvinsBagTopics topics, BagCompression compression)
    : bag_(path, compression), topics_(std::move(topics)), imageSeq_(topics_.cameras.size(), 0) {}

void GvinsBagWriter::writeImu(const vio::ImuSample& s) {
  const ros::ImuMsg m = toImuMsg(s, imuSeq_++);
  bag_.write(topics_.imu, ros::imuType(), m.header.stamp, ros::serialize(m));
}

void GvinsBagWriter::writeImage(int camera, std::int64_t t_ns, const cv::Mat& image) {
  const auto c = static_cast<std::size_t>(camera);
  if (camera < 0 || c >= topics_.cameras.size()) throw std::out_of_range("GvinsBagWriter: no topic for camera " + std::to_string(camera));
  const ros::ImageMsg m = toImageMsg(image, t_ns, imageSeq_[c]++, "cam" + std::to_string(camera));
  bag_.write(topics_.cameras[c], ros::imageType(), m.header.stamp, ros::serialize(m));
}

void GvinsBagWriter::writeEpoch(const ObsEpoch& epoch, const GlonassChannels& channels, BagConvertStats* stats) {
  const ros::GnssMeasMsg m = toGnssMeasMsg(epoch, channels, stats);
  bag_.write(topics_.gnssMeas, ros::gnssMeasType(), toRosTime(gpstNanoseconds(epoch.time)), ros::serialize(m));
}

void GvinsBagWriter::writeEphemeris(const KeplerEphemeris& eph, std::int64_t record_t_ns) {
  if (gnssCommSat(eph.sat) == 0) return;  // QZSS etc.: not representable
  bag_.write(topics_.ephem, ros::gnssEphemType(), toRosTime(record_t_ns), ros::serialize(toGnssEphemMsg(eph)));
}

void GvinsBagWriter::writeEphemeris(const GlonassEphemeris& eph, std::int64_t record_t_ns) {
  bag_.write(topics_.gloEphem, ros::gnssGloEphemType(), toRosTime(record_t_ns),
             ros::serialize(toGnssGloEphemMsg(eph)));
}

// ---- conversions -----------------------------------------------------------------------------

std::string BagConversionSummary::text() const {
  std::ostringstream s;
  s << "  IMU samples          " << imu << "\n"
    << "  images               " << images << "\n"
    << "  GNSS epochs          " << gnssEpochs << "\n"
    << "  ephemerides          " << ephemerides << "\n"
    << "  skipped satellites   " << convert.unknownSatellites << " (no gnss_comm number: QZSS/SBAS/NavIC)\n"
    << "  skipped signals      " << convert.unknownSignals + convert.duplicateSignals + convert.glonassNoChannel
    << "\n";
  return s.str();
}

BagConversionSummary datasetToBag(const std::string& datasetDir, const std::string& bagPath,
                                  const DatasetToBagOptions& options) {
  BagConversionSummary sum;
  vio::EurocDataset data(datasetDir);
  std::string obsPath = options.gnssObs, navPath = options.gnssNav;
  const fs::path gnssDir = fs::path(datasetDir) / "gnss";
  if (obsPath.empty() && fs::exists(gnssDir / "rover.obs")) obsPath = (gnssDir / "rover.obs").string();
  if (navPath.empty() && fs::exists(gnssDir / "nav.rnx")) navPath = (gnssDir / "nav.rnx").string();
  NavData nav;
  if (!navPath.empty()) nav = readRinexNav(navPath);

  GvinsBagWriter w(bagPath, options.topics, options.compression);
  std::int64_t first = std::numeric_limits<std::int64_t>::max();
  for (const vio::ImuSample& s : data.imu()) {
    w.writeImu(s);
    first = std::min(first, s.t_ns);
    ++sum.imu;
  }
  for (int cam = 0; cam < data.cameraCount() && cam < static_cast<int>(options.topics.cameras.size()); ++cam) {
    const auto& entries = data.cameraEntries(cam);
    for (std::size_t i = 0; i < entries.size(); ++i) {
      w.writeImage(cam, entries[i].t_ns, data.loadImage(cam, i));
      first = std::min(first, entries[i].t_ns);
      ++sum.images;
    }
    std::fprintf(stderr, "gvins-bag: cam%d: %zu images\n", cam, entries.size());
  }
  GlonassChannels channels;
  for (const GlonassEphemeris& g : nav.glonass) channels.set(g.sat.prn, g.frequencyChannel);
  if (!obsPath.empty()) {
    RinexObsReader reader(obsPath);
    channels.mergeMissing(reader.header().glonassChannels);
    ObsEpoch e;
    while (reader.next(e)) {
      if (sum.gnssEpochs == 0) first = std::min(first, gpstNanoseconds(e.time));
      w.writeEpoch(e, channels, &sum.convert);
      ++sum.gnssEpochs;
    }
  }
  if (first == std::numeric_limits<std::int64_t>::max()) first = 1;
  for (const KeplerEphemeris& k : nav.kepler) {
    if (gnssCommSat(k.sat) == 0) continue;
    w.writeEphemeris(k, first);
    ++sum.ephemerides;
  }
  for (const GlonassEphemeris& g : nav.glonass) {
    w.writeEphemeris(g, first);
    ++sum.ephemerides;
  }
  w.close();
  return sum;
}

namespace {

class CsvOut {
 public:
  explicit CsvOut(const fs::path& p) : path_(p), f_(p) {
    if (!f_) throw std::runtime_error("cannot create " + p.string());
  }
  CsvOut& num(double v) {
    char buf[64];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    f_.write(buf, r.ptr - buf);
    return *this;
  }
  CsvOut& integer(std::int64_t v) {
    f_ << v;
    return *this;
  }
  CsvOut& text(const std::string& s) {
    f_ << s;
    return *this;
  }
  void close() {
    f_.close();
    if (!f_) throw std::runtime_error("write error on " + path_.string());
  }

 private:
  fs::path path_;
  std::ofstream f_;
};

}  // namespace

BagConversionSummary bagToDataset(const std::string& bagPath, const std::string& datasetDir,
                                  const BagToDatasetOptions& options) {
  BagConversionSummary sum;
  GvinsBagReader reader(bagPath, options.topics);
  const fs::path mav0 = fs::path(datasetDir) / "mav0";
  fs::create_directories(mav0 / "imu0");
  CsvOut imu(mav0 / "imu0" / "data.csv");
  imu.text("#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
           "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n");
  std::vector<std::unique_ptr<CsvOut>> camCsv(options.topics.cameras.size());
  std::vector<ObsEpoch> epochs;
  NavData nav;
  GvinsBagItem item;
  while (reader.next(item)) {
    switch (item.kind) {
      case GvinsBagItem::Kind::Imu:
        imu.integer(item.imu.t_ns);
        for (int i = 0; i < 3; ++i) imu.text(",").num(item.imu.gyro[i]);
        for (int i = 0; i < 3; ++i) imu.text(",").num(item.imu.accel[i]);
        imu.text("\n");
        ++sum.imu;
        break;
      case GvinsBagItem::Kind::Image: {
        const auto c = static_cast<std::size_t>(item.camera);
        const fs::path dir = mav0 / ("cam" + std::to_string(item.camera));
        if (!camCsv[c]) {
          fs::create_directories(dir / "data");
          camCsv[c] = std::make_unique<CsvOut>(dir / "data.csv");
          camCsv[c]->text("#timestamp [ns],filename\n");
        }
        const std::string name = std::to_string(item.image_t_ns) + ".png";
        if (!cv::imwrite((dir / "data" / name).string(), item.image))
          throw std::runtime_error("cannot write " + (dir / "data" / name).string());
        camCsv[c]->integer(item.image_t_ns).text(",").text(name).text("\n");
        ++sum.images;
        break;
      }
      case GvinsBagItem::Kind::GnssEpoch:
        epochs.push_back(std::move(item.epoch));
        ++sum.gnssEpochs;
        break;
      case GvinsBagItem::Kind::Ephemeris:
        nav.kepler.push_back(item.kepler);
        ++sum.ephemerides;
        break;
      case GvinsBagItem::Kind::GlonassEphemeris:
        nav.glonass.push_back(item.glonass);
        ++sum.ephemerides;
        break;
    }
    const std::int64_t n = sum.imu + sum.images + sum.gnssEpochs + sum.ephemerides;
    if (n % 20000 == 0) std::fprintf(stderr, "gvins-bag: %lld messages\n", static_cast<long long>(n));
  }
  imu.close();
  for (auto& c : camCsv)
    if (c) c->close();
  sum.convert = reader.stats().convert;
  if (!options.calibrationFrom.empty()) {
    const fs::path from = fs::path(options.calibrationFrom);
    const fs::path fromMav0 = fs::exists(from / "mav0") ? from / "mav0" : from;
    for (const char* sensor : {"imu0", "cam0", "cam1"}) {
      const fs::path src = fromMav0 / sensor / "sensor.yaml";
      if (fs::exists(src) && fs::exists(mav0 / sensor))
        fs::copy_file(src, mav0 / sensor / "sensor.yaml", fs::copy_options::overwrite_existing);
    }
    if (fs::exists(fromMav0 / "body.yaml"))
      fs::copy_file(fromMav0 / "body.yaml", mav0 / "body.yaml", fs::copy_options::overwrite_existing);
  }
  if (!epochs.empty() || !nav.kepler.empty() || !nav.glonass.empty()) {
    const fs::path gnss = fs::path(datasetDir) / "gnss";
    fs::create_directories(gnss);
    if (!epochs.empty()) {
      RinexObsHeader h;
      h.station.markerName = "GVINS_BAG";
      h.signalStrengthUnit = "DBHZ";
      for (const ObsEpoch& e : epochs) h.addTypesFrom(e);
      h.glonassChannels = reader.glonassChannels();
      std::ofstream f(gnss / "rover.obs");
      RinexObsWriter w(f, h, "gvins-bag");
      for (const ObsEpoch& e : epochs) w.write(e);
      w.finish();
      if (!f) throw std::runtime_error("write error on " + (gnss / "rover.obs").string());
    }
    if (!nav.kepler.empty() || !nav.glonass.empty()) {
      std::ofstream f(gnss / "nav.rnx");
      writeRinexNav(f, nav, "gvins-bag");
      if (!f) throw std::runtime_error("write error on " + (gnss / "nav.rnx").string());
    }
  }
  return sum;
}

}  // namespace gvins::fusion
