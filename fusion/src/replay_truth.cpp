// Antenna truth tracks for the global evaluation of the replay: gvins-sim ECEF truth files and
// .pos solutions (replay_pipeline.hpp).
#include <charconv>
#include <cmath>

#include "gvins/base/line_reader.hpp"
#include "gvins/base/parse_error.hpp"
#include "gvins/base/text_fields.hpp"
#include "gvins/fusion/replay_pipeline.hpp"

namespace gvins::fusion {

namespace {
std::vector<EcefTruthSample> parseEcefTruth(LineReader& r) {
  std::vector<EcefTruthSample> out;
  std::string line;
  while (r.next(line)) {
    std::string_view l = line;
    if (!l.empty() && l.back() == '\r') l.remove_suffix(1);
    const std::string_view t = trim(l);
    if (t.empty() || t.front() == '#') continue;
    const TextLocation where = r.location();
    std::vector<std::string_view> f;
    std::size_t start = 0;
    for (;;) {
      const std::size_t c = l.find(',', start);
      f.push_back(trim(l.substr(start, c == std::string_view::npos ? std::string_view::npos : c - start)));
      if (c == std::string_view::npos) break;
      start = c + 1;
    }
    if (f.size() < 14)
      throwParseError(where, f.size() < 12 ? "line" : (f.size() == 12 ? "antenna_E_y" : "antenna_E_z"),
                      "expected at least 14 fields (antenna position in columns 12-14), found " + std::to_string(f.size()));
    EcefTruthSample s;
    {
      const std::string_view st = f[0];
      const auto res = std::from_chars(st.data(), st.data() + st.size(), s.t_ns);
      if (st.empty() || res.ec != std::errc() || res.ptr != st.data() + st.size() || s.t_ns < 0)
        throwParseError(where, "timestamp", "not a non-negative integer nanosecond stamp: '" + std::string(st) + "'");
    }
    s.antenna = {parseDouble(f[11], where, "antenna_E_x"), parseDouble(f[12], where, "antenna_E_y"),
                 parseDouble(f[13], where, "antenna_E_z")};
    if (!s.antenna.allFinite()) throwParseError(where, "antenna_E_x", "antenna position is not finite");
    if (f.size() >= 17) {
      const Eigen::Vector3d v(parseDouble(f[14], where, "antenna_v_E_x"), parseDouble(f[15], where, "antenna_v_E_y"),
                              parseDouble(f[16], where, "antenna_v_E_z"));
      if (!v.allFinite()) throwParseError(where, "antenna_v_E_x", "antenna velocity is not finite");
      s.antennaVelocity = v;
    }
    if (!out.empty() && s.t_ns <= out.back().t_ns)
      throwParseError(where, "timestamp", "time stamps must increase strictly");
    out.push_back(s);
  }
  return out;
}
}  // namespace

std::vector<EcefTruthSample> ecefTruthFromPos(const PosFile& pos, int maxQuality, std::int64_t sensorToGpst_ns) {
  std::vector<EcefTruthSample> out;
  for (const PositionSolution& s : pos.solutions) {
    const int q = static_cast<int>(s.quality);
    if (q < 1 || q > maxQuality) continue;
    EcefTruthSample x;
    x.t_ns = s.time.wholeSeconds() * 1'000'000'000 + static_cast<std::int64_t>(std::llround(s.time.fraction() * 1e9)) -
             sensorToGpst_ns;
    x.antenna = s.position;
    x.antennaVelocity = s.velocity;
    if (!out.empty() && x.t_ns <= out.back().t_ns) continue;
    out.push_back(x);
  }
  return out;
}

std::vector<EcefTruthSample> readEcefTruthCsv(const std::string& path) {
  LineReader r(path, 16384);
  return parseEcefTruth(r);
}

std::vector<EcefTruthSample> parseEcefTruthCsv(std::string_view text, const std::string& name) {
  LineReader r(text, name, 16384);
  return parseEcefTruth(r);
}

}  // namespace gvins::fusion
