#include "gvins/vio/tum_trajectory.hpp"

#include <cinttypes>
#include <cmath>
#include <stdexcept>

#include <Eigen/Geometry>

#include "csv_fields.hpp"
#include "gvins/base/line_reader.hpp"

namespace gvins::vio {

namespace {
std::vector<TumPose> parseLines(LineReader& reader, TumTimeUnit unit, std::vector<std::size_t>* resetMarks) {
  static constexpr const char* kFields[8] = {"timestamp", "x", "y", "z", "qx", "qy", "qz", "qw"};
  std::vector<TumPose> out;
  std::string line;
  std::vector<std::string_view> f;
  if (resetMarks) resetMarks->clear();
  const std::string mark = "# " + std::string(kTumResetMark);
  while (reader.next(line)) {
    if (detail::isCommentOrBlank(line)) {
      if (resetMarks && line.rfind(mark, 0) == 0 && (resetMarks->empty() || resetMarks->back() != out.size())) {
        resetMarks->push_back(out.size());
      }
      continue;
    }
    const TextLocation where = reader.location();
    detail::splitFields(line, line.find(',') == std::string::npos, f);
    if (f.size() != 8) {
      throwParseError(where, f.size() < 8 ? kFields[f.size()] : "line",
                      "expected 8 fields (t x y z qx qy qz qw), found " + std::to_string(f.size()));
    }
    TumPose p;
    p.t_ns = unit == TumTimeUnit::Seconds ? detail::parseSecondsToNanoseconds(f[0], where, "timestamp")
                                          : detail::parseNanoseconds(f[0], where, "timestamp");
    double v[8];
    for (int k = 1; k < 8; ++k) v[k] = parseDouble(f[static_cast<std::size_t>(k)], where, kFields[k]);
    p.p = {v[1], v[2], v[3]};
    Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    const double n = q.norm();
    if (std::abs(n - 1.0) > 1e-3) throwParseError(where, "qw", "quaternion norm " + std::to_string(n) + " is not 1");
    q.coeffs() /= n;
    p.R = q.toRotationMatrix();
    if (!out.empty() && p.t_ns <= out.back().t_ns) {
      throwParseError(where, "timestamp", p.t_ns == out.back().t_ns ? "duplicate time stamp"
                                                                    : "time stamp before the previous one");
    }
    out.push_back(p);
  }
  return out;
}
}  // namespace

std::vector<TumPose> readTumTrajectory(const std::string& path, TumTimeUnit unit, std::vector<std::size_t>* resetMarks) {
  LineReader r(path);
  return parseLines(r, unit, resetMarks);
}

std::vector<TumPose> parseTumTrajectory(std::string_view text, const std::string& name, TumTimeUnit unit,
                                        std::vector<std::size_t>* resetMarks) {
  LineReader r(text, name);
  return parseLines(r, unit, resetMarks);
}

TumTrajectoryWriter::TumTrajectoryWriter(const std::string& path, const std::string& header) : path_(path) {
  f_ = std::fopen(path.c_str(), "w");
  if (!f_) throw std::runtime_error("cannot create trajectory file " + path);
  if (!header.empty()) std::fprintf(f_, "# %s\n", header.c_str());
}

TumTrajectoryWriter::~TumTrajectoryWriter() {
  if (f_) std::fclose(f_);
}

void TumTrajectoryWriter::write(const TumPose& pose) {
  if (!f_) throw std::runtime_error("trajectory file " + path_ + " is closed");
  Eigen::Quaterniond q(pose.R);
  q.normalize();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const std::int64_t t = pose.t_ns;
  if (t < 0) throw std::invalid_argument("negative time stamp in a TUM trajectory");
  std::fprintf(f_, "%" PRId64 ".%09" PRId64 " %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n", t / 1000000000,
               t % 1000000000, pose.p.x(), pose.p.y(), pose.p.z(), q.x(), q.y(), q.z(), q.w());
}

void TumTrajectoryWriter::comment(const std::string& text) {
  if (!f_) throw std::runtime_error("trajectory file " + path_ + " is closed");
  if (text.find_first_of("\r\n") != std::string::npos) throw std::invalid_argument("TUM comment with a line break");
  std::fprintf(f_, "# %s\n", text.c_str());
}

void TumTrajectoryWriter::close() {
  if (!f_) return;
  const bool err = std::ferror(f_) != 0;
  const bool closeErr = std::fclose(f_) != 0;
  f_ = nullptr;
  if (err || closeErr) throw std::runtime_error("error writing trajectory file " + path_);
}

void writeTumTrajectory(const std::string& path, const std::vector<TumPose>& poses) {
  TumTrajectoryWriter w(path);
  for (const auto& p : poses) w.write(p);
  w.close();
}

}  // namespace gvins::vio
