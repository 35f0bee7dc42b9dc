#include "gvins/fusion/replay_feature_tracks.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <system_error>

#include "gvins/base/line_reader.hpp"
#include "gvins/base/text_fields.hpp"

namespace gvins::fusion {

namespace {

std::int64_t parseStamp(std::string_view s, const TextLocation& where) {
  s = trim(s);
  std::int64_t v = 0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || r.ec != std::errc() || r.ptr != s.data() + s.size() || v < 0)
    throwParseError(where, "timestamp", "not a non-negative integer nanosecond stamp: '" + std::string(s) + "'");
  return v;
}

std::uint64_t parseId(std::string_view s, const TextLocation& where) {
  s = trim(s);
  std::uint64_t v = 0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || r.ec != std::errc() || r.ptr != s.data() + s.size())
    throwParseError(where, "landmark_id", "not an unsigned integer: '" + std::string(s) + "'");
  return v;
}

std::vector<TrackStamp> parse(LineReader& reader) {
  std::vector<TrackStamp> out;
  std::string line;
  std::vector<std::string_view> f;
  while (reader.next(line)) {
    std::string_view l = line;
    if (!l.empty() && l.back() == '\r') l.remove_suffix(1);
    const std::string_view t = trim(l);
    if (t.empty() || t.front() == '#') continue;
    const TextLocation where = reader.location();
    f.clear();
    std::size_t start = 0;
    for (;;) {
      const std::size_t c = l.find(',', start);
      f.push_back(l.substr(start, c == std::string_view::npos ? std::string_view::npos : c - start));
      if (c == std::string_view::npos) break;
      start = c + 1;
    }
    static const char* const kNames[] = {"timestamp", "landmark_id", "u", "v"};
    if (f.size() != 4)
      throwParseError(where, f.size() < 4 ? kNames[f.size()] : "line",
                      "expected 4 fields (timestamp, landmark_id, u, v), found " + std::to_string(f.size()));
    const std::int64_t stamp = parseStamp(f[0], where);
    TrackObservation o;
    o.id = parseId(f[1], where);
    o.pixel = {parseDouble(trim(f[2]), where, "u"), parseDouble(trim(f[3]), where, "v")};
    if (!std::isfinite(o.pixel.x()) || !std::isfinite(o.pixel.y()))
      throwParseError(where, std::isfinite(o.pixel.x()) ? "v" : "u", "pixel coordinate is not finite");
    if (out.empty() || stamp > out.back().t_ns) {
      out.push_back({stamp, {}});
    } else if (stamp < out.back().t_ns) {
      throwParseError(where, "timestamp", "time stamp before the previous one");
    }
    for (const TrackObservation& p : out.back().obs)
      if (p.id == o.id) throwParseError(where, "landmark_id", "landmark " + std::to_string(o.id) + " listed twice at one stamp");
    out.back().obs.push_back(o);
  }
  return out;
}

}  // namespace

std::vector<TrackStamp> readFeatureTracksCsv(const std::string& path) {
  LineReader r(path);
  return parse(r);
}

std::vector<TrackStamp> parseFeatureTracksCsv(std::string_view text, const std::string& name) {
  LineReader r(text, name);
  return parse(r);
}

std::vector<TrackStamp> withImageStamps(std::vector<TrackStamp> tracks, const std::vector<std::int64_t>& images) {
  std::vector<TrackStamp> out;
  out.reserve(std::max(tracks.size(), images.size()));
  std::size_t k = 0;
  for (TrackStamp& t : tracks) {
    for (; k < images.size() && images[k] < t.t_ns; ++k) {
      if (out.empty() || images[k] > out.back().t_ns) out.push_back({images[k], {}});
    }
    if (k < images.size() && images[k] == t.t_ns) ++k;
    out.push_back(std::move(t));
  }
  for (; k < images.size(); ++k) {
    if (out.empty() || images[k] > out.back().t_ns) out.push_back({images[k], {}});
  }
  return out;
}

FeatureTrackFrames::FeatureTrackFrames(std::vector<TrackStamp> cam0, const vio::CameraModel& model0,
                                       std::vector<TrackStamp> cam1, const vio::CameraModel* model1)
    : cam0_(std::move(cam0)), cam1_(std::move(cam1)), model0_(&model0), model1_(model1) {}

vio::FeatureFrame FeatureTrackFrames::frame(std::size_t i) {
  const TrackStamp& s = cam0_.at(i);
  vio::FeatureFrame f;
  f.t_ns = s.t_ns;
  f.index = i;
  while (cam1Next_ < cam1_.size() && cam1_[cam1Next_].t_ns < s.t_ns) ++cam1Next_;
  const TrackStamp* right =
      (model1_ && cam1Next_ < cam1_.size() && cam1_[cam1Next_].t_ns == s.t_ns) ? &cam1_[cam1Next_] : nullptr;
  std::vector<std::pair<std::uint64_t, int>> lengths;
  lengths.reserve(s.obs.size());
  for (const TrackObservation& o : s.obs) {
    vio::FeatureObservation fo;
    fo.id = o.id;
    const auto it = std::lower_bound(lengths_.begin(), lengths_.end(), std::make_pair(o.id, 0));
    fo.trackLength = (it != lengths_.end() && it->first == o.id) ? it->second + 1 : 1;
    fo.pixel0 = o.pixel;
    fo.normalized0 = model0_->undistort(o.pixel);
    if (right) {
      for (const TrackObservation& r : right->obs) {
        if (r.id != o.id) continue;
        fo.stereo = true;
        fo.pixel1 = r.pixel;
        fo.normalized1 = model1_->undistort(r.pixel);
        break;
      }
    }
    lengths.emplace_back(o.id, fo.trackLength);
    f.features.push_back(fo);
  }
  std::sort(lengths.begin(), lengths.end());
  lengths_ = std::move(lengths);
  return f;
}

namespace fs = std::filesystem;

struct FeatureTrackDatasetWriter::File {
  std::string path;
  std::FILE* f = nullptr;
  ~File() {
    if (f) std::fclose(f);
  }
};

namespace {

void linkEntry(const fs::path& target, const fs::path& link) {
  std::error_code ec;
  fs::create_symlink(fs::absolute(target), link, ec);
  if (ec) throw std::runtime_error("cannot create the link " + link.string() + ": " + ec.message());
}

void makeDir(const fs::path& d) {
  std::error_code ec;
  fs::create_directories(d, ec);
  if (ec || !fs::is_directory(d)) throw std::runtime_error("cannot create the folder " + d.string());
}

bool isCameraDir(const fs::directory_entry& e) {
  const std::string n = e.path().filename().string();
  return e.is_directory() && n.size() > 3 && n.compare(0, 3, "cam") == 0 &&
         n.find_first_not_of("0123456789", 3) == std::string::npos;
}

}  // namespace

FeatureTrackDatasetWriter::FeatureTrackDatasetWriter(const std::string& sourceDataset, const std::string& dir,
                                                     int cameras) {
  if (cameras < 1 || cameras > 2) throw std::invalid_argument("FeatureTrackDatasetWriter: 1 or 2 cameras");
  const fs::path src(sourceDataset), dst(dir);
  if (fs::exists(dst) && !(fs::is_directory(dst) && fs::is_empty(dst)))
    throw std::runtime_error("track dataset folder " + dst.string() + " exists and is not empty");
  fs::path srcMav0 = src / "mav0";
  makeDir(dst / "mav0");
  if (fs::is_directory(srcMav0)) {
    for (const auto& e : fs::directory_iterator(src))
      if (e.path().filename() != "mav0") linkEntry(e.path(), dst / e.path().filename());
  } else {
    srcMav0 = src;
  }
  for (const auto& e : fs::directory_iterator(srcMav0)) {
    const fs::path name = e.path().filename();
    if (!isCameraDir(e)) {
      linkEntry(e.path(), dst / "mav0" / name);
      continue;
    }
    makeDir(dst / "mav0" / name);
    for (const auto& c : fs::directory_iterator(e.path())) {
      const fs::path cn = c.path().filename();
      if (cn == "data" || cn == "features.csv") continue;  // images; the tracks are written here
      linkEntry(c.path(), dst / "mav0" / name / cn);
    }
  }
  for (int c = 0; c < cameras; ++c) {
    auto file = std::make_unique<File>();
    const fs::path camDir = dst / "mav0" / ("cam" + std::to_string(c));
    makeDir(camDir);
    file->path = (camDir / "features.csv").string();
    file->f = std::fopen(file->path.c_str(), "w");
    if (!file->f) throw std::runtime_error("cannot create " + file->path);
    std::fputs("#timestamp [ns],landmark_id,u [px],v [px]  (tracks of the gvins-replay image front end)\n", file->f);
    files_.push_back(std::move(file));
  }
}

FeatureTrackDatasetWriter::~FeatureTrackDatasetWriter() = default;

void FeatureTrackDatasetWriter::write(const vio::FeatureFrame& frame) {
  order_.clear();
  for (std::size_t i = 0; i < frame.features.size(); ++i) order_.emplace_back(frame.features[i].id, i);
  std::sort(order_.begin(), order_.end());
  for (std::size_t c = 0; c < files_.size(); ++c) {
    std::FILE* f = files_[c]->f;
    for (const auto& [id, i] : order_) {
      const vio::FeatureObservation& o = frame.features[i];
      if (c == 1 && !o.stereo) continue;
      const Eigen::Vector2d& px = c == 0 ? o.pixel0 : o.pixel1;
      std::fprintf(f, "%lld,%llu,%.6f,%.6f\n", static_cast<long long>(frame.t_ns), static_cast<unsigned long long>(id),
                   px.x(), px.y());
    }
  }
}

void FeatureTrackDatasetWriter::close() {
  for (auto& file : files_) {
    if (!file->f) continue;
    const bool bad = std::ferror(file->f) != 0;
    const bool closeFailed = std::fclose(file->f) != 0;
    file->f = nullptr;
    if (bad || closeFailed) throw std::runtime_error("write error on " + file->path);
  }
}

}  // namespace gvins::fusion
