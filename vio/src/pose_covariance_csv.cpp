#include "gvins/vio/pose_covariance_csv.hpp"

#include <cinttypes>
#include <cmath>
#include <stdexcept>

#include "csv_fields.hpp"
#include "gvins/base/line_reader.hpp"

namespace gvins::vio {

namespace {
std::string entryName(int i, int j) { return "c" + std::to_string(i) + std::to_string(j); }

std::vector<PoseCovariance> parseLines(LineReader& reader) {
  std::vector<PoseCovariance> out;
  std::string line;
  std::vector<std::string_view> f;
  while (reader.next(line)) {
    if (detail::isCommentOrBlank(line)) continue;
    const TextLocation where = reader.location();
    detail::splitFields(line, line.find(',') == std::string::npos, f);
    if (f.size() != 37) {
      throwParseError(where, f.size() < 37 ? (f.empty() ? std::string("timestamp") : entryName(static_cast<int>(f.size() - 1) / 6, static_cast<int>(f.size() - 1) % 6)) : std::string("line"),
                      "expected 37 fields (t and 36 covariance entries), found " + std::to_string(f.size()));
    }
    PoseCovariance c;
    c.t_ns = detail::parseSecondsToNanoseconds(f[0], where, "timestamp");
    double maxAbs = 0.0;
    for (int i = 0; i < 6; ++i) {
      for (int j = 0; j < 6; ++j) {
        const std::string name = entryName(i, j);
        const double v = parseDouble(f[static_cast<std::size_t>(1 + 6 * i + j)], where, name);
        if (!std::isfinite(v)) throwParseError(where, name, "covariance entry is not finite");
        c.P(i, j) = v;
        maxAbs = std::max(maxAbs, std::abs(v));
      }
    }
    for (int i = 0; i < 6; ++i) {
      if (c.P(i, i) < 0.0) throwParseError(where, entryName(i, i), "negative variance");
      for (int j = i + 1; j < 6; ++j) {
        if (std::abs(c.P(i, j) - c.P(j, i)) > 1e-6 * maxAbs + 1e-12)
          throwParseError(where, entryName(j, i), "covariance is not symmetric (differs from " + entryName(i, j) + ")");
      }
    }
    c.P = 0.5 * (c.P + c.P.transpose()).eval();
    if (!out.empty() && c.t_ns <= out.back().t_ns) {
      throwParseError(where, "timestamp", c.t_ns == out.back().t_ns ? "duplicate time stamp"
                                                                    : "time stamp before the previous one");
    }
    out.push_back(c);
  }
  return out;
}
}  // namespace

std::vector<PoseCovariance> readPoseCovarianceCsv(const std::string& path) {
  LineReader r(path, 8192);
  return parseLines(r);
}

std::vector<PoseCovariance> parsePoseCovarianceCsv(std::string_view text, const std::string& name) {
  LineReader r(text, name, 8192);
  return parseLines(r);
}

PoseCovarianceWriter::PoseCovarianceWriter(const std::string& path) : path_(path) {
  f_ = std::fopen(path.c_str(), "w");
  if (!f_) throw std::runtime_error("cannot create covariance file " + path);
  std::fprintf(f_, "# t [s], 6x6 covariance of [dtheta_body (rad); dp_world (m)], row-major\n");
}

PoseCovarianceWriter::~PoseCovarianceWriter() {
  if (f_) std::fclose(f_);
}

void PoseCovarianceWriter::write(std::int64_t t_ns, const Matrix6d& P) {
  if (!f_) throw std::runtime_error("covariance file " + path_ + " is closed");
  if (t_ns < 0) throw std::invalid_argument("negative time stamp in a covariance file");
  const Matrix6d S = 0.5 * (P + P.transpose());
  std::fprintf(f_, "%" PRId64 ".%09" PRId64, t_ns / 1000000000, t_ns % 1000000000);
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) std::fprintf(f_, ",%.9g", S(i, j));
  std::fputc('\n', f_);
}

void PoseCovarianceWriter::close() {
  if (!f_) return;
  const bool err = std::ferror(f_) != 0;
  const bool closeErr = std::fclose(f_) != 0;
  f_ = nullptr;
  if (err || closeErr) throw std::runtime_error("error writing covariance file " + path_);
}

}  // namespace gvins::vio
