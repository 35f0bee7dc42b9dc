// RINEX clock reader and writer.
//
// Layouts from "RINEX Extensions to Handle Clock Information" 2.00 (Ray & Gurtner 1999), 3.02
// (2010) and 3.04 (IGS/RTCM-SC104, 2017):
//   header labels in columns 61-80;  RINEX VERSION / TYPE: F9.2 version, file type 'C';
//   TIME SYSTEM ID: 3X,A3;  # / TYPES OF DATA: I6, 9(4X,A2);  LEAP SECONDS: I6
//   data record (2.00-3.02): A2,1X,A4,1X,I4,4I3,F10.6,I3,2X,E19.12,E20.12
//   data record (3.04):      A2,1X,A9,1X,I4,4I3,F10.6,I3,2X,E19.12,E20.12  (the name field grew
//                            from A4 to A9, shifting everything after it by 5 columns)
//   continuation line (more than 2 values): E19.12, up to 3 E20.12.
// AS values: clock bias (s), its sigma, rate, rate sigma, acceleration, its sigma (1 to 6 values).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <ostream>
#include <string>

#include "gvins/base/line_reader.hpp"
#include "gvins/base/text_fields.hpp"
#include "gvins/ephemeris/rinex_clock.hpp"
#include "product_time_scale.hpp"

namespace gvins {
namespace {

constexpr int kMaxValues = 6;  // AS/AR: bias, sigma, rate, sigma, acceleration, sigma

bool endsWithLabel(std::string_view line, std::string_view label) {
  while (!line.empty() && (line.back() == ' ' || line.back() == '\r')) line.remove_suffix(1);
  // The label must start at or after column 61 (index 60).
  return line.size() >= 60 + label.size() && line.substr(line.size() - label.size()) == label;
}

// Splits at blanks into at most `max` tokens; returns the number found (more than max -> max+1).
std::size_t tokens(std::string_view text, std::string_view* out, std::size_t max) {
  std::size_t n = 0, i = 0;
  while (true) {
    while (i < text.size() && (text[i] == ' ' || text[i] == '\r')) ++i;
    if (i >= text.size()) break;
    const std::size_t start = i;
    while (i < text.size() && text[i] != ' ' && text[i] != '\r') ++i;
    if (n == max) return max + 1;
    out[n++] = text.substr(start, i - start);
  }
  return n;
}

int intToken(std::string_view text, const TextLocation& where, std::string_view field, long lo, long hi) {
  const long v = parseInt(text, where, field);
  if (v < lo || v > hi) throwParseError(where, field, "value " + std::to_string(v) + " out of range");
  return static_cast<int>(v);
}

class ClockReader {
 public:
  explicit ClockReader(LineReader& in) : in_(in) {}
  ClockData run();

 private:
  LineReader& in_;
  ClockData d_;
  std::string_view line_;
  std::vector<std::vector<std::int64_t>> lines_;  // line number of each record, per satellite

  TextLocation here() const { return in_.location(); }
  void readHeader();
  void readRecord();
  void finish();
};

void ClockReader::readHeader() {
  if (!in_.next(line_)) throwParseError(here(), "RINEX VERSION / TYPE", "empty file");
  if (!endsWithLabel(line_, "RINEX VERSION / TYPE")) {
    throwParseError(here(), "RINEX VERSION / TYPE", "first line is not 'RINEX VERSION / TYPE'");
  }
  d_.version = parseFiniteDouble(trimmedColumn(line_, 0, 9), here(), "RINEX version");
  if (d_.version < 2.0 || d_.version >= 4.0) {
    throwParseError(here(), "RINEX version", "unsupported clock RINEX version " + std::string(trimmedColumn(line_, 0, 9)));
  }
  const std::string_view type = trimmedColumn(line_, 9, 31);
  if (type.empty() || type[0] != 'C') throwParseError(here(), "file type", "not a clock file (type 'C')");
  while (true) {
    if (!in_.next(line_)) throwParseError(here(), "END OF HEADER", "missing 'END OF HEADER'");
    if (endsWithLabel(line_, "END OF HEADER")) break;
    if (endsWithLabel(line_, "TIME SYSTEM ID")) {
      const std::string ts(trimmedColumn(line_, 0, 60));
      if (!isProductTimeSystem(ts)) throwParseError(here(), "TIME SYSTEM ID", "unknown time system '" + ts + "'");
      d_.timeSystem = ts;
    } else if (endsWithLabel(line_, "LEAP SECONDS")) {
      intToken(trimmedColumn(line_, 0, 6), here(), "LEAP SECONDS", -100, 100);
    } else if (endsWithLabel(line_, "# / TYPES OF DATA")) {
      const int n = intToken(trimmedColumn(line_, 0, 6), here(), "# / TYPES OF DATA", 0, 9);
      for (int k = 0; k < n; ++k) {
        const std::string_view t = trimmedColumn(line_, 10 + 6 * static_cast<std::size_t>(k), 2);
        if (t != "AS" && t != "AR" && t != "CR" && t != "DR" && t != "MS") {
          throwParseError(here(), "# / TYPES OF DATA", "unknown data type '" + std::string(t) + "'");
        }
      }
    }
    // Other header records (PGM / RUN BY / DATE, ANALYSIS CENTER, PRN LIST, ...) are not needed.
  }
}

// Data values are E19.12 / E20.12 (RINEX clock 3.04, section 5 and table A5: "-0.123456789012E-03").
// A value without its exponent of at least two digits has lost characters (a file cut inside a
// number) and must not be read as a different number (-7.670588 s for -7.670588E-05 s).
double clockValue(std::string_view tok, const TextLocation& where, std::string_view field) {
  const std::size_t e = tok.find_first_of("EeDd");
  std::size_t digits = 0;
  if (e != std::string_view::npos) {
    std::size_t k = e + 1;
    if (k < tok.size() && (tok[k] == '+' || tok[k] == '-')) ++k;
    digits = tok.size() - k;
  }
  if (digits < 2) {
    throwParseError(where, field, "'" + std::string(tok) + "' is not a complete E19.12 value (exponent missing or cut off)");
  }
  return parseFiniteDouble(tok, where, field);
}

void ClockReader::readRecord() {
  const std::string_view type = column(line_, 0, 2);
  const bool sat = type == "AS";
  if (!sat && type != "AR" && type != "CR" && type != "DR" && type != "MS") {
    throwParseError(here(), "record type", "unknown clock record type '" + std::string(type) + "'");
  }
  const std::size_t nameWidth = d_.version >= 3.04 - 1e-9 ? 9 : 4;
  const std::string_view name = trimmedColumn(line_, 3, nameWidth);
  if (name.empty()) throwParseError(here(), "name", "missing receiver/satellite name");
  if (name.find(' ') != std::string_view::npos) {
    throwParseError(here(), "name", "blank inside the name field '" + std::string(name) + "' (A" +
                                        std::to_string(nameWidth) + " in version " +
                                        (nameWidth == 9 ? "3.04: a 3.00-layout record?)" : "2.00-3.03)"));
  }
  if (line_.size() > 3 + nameWidth && line_[3 + nameWidth] != ' ') {
    throwParseError(here(), "name", std::string("name wider than the A") + std::to_string(nameWidth) + " field of version " +
                                        (nameWidth == 9 ? "3.04" : "2.00-3.03"));
  }
  std::string_view tok[10];
  const std::size_t n = tokens(line_.size() > 3 + nameWidth ? line_.substr(3 + nameWidth) : std::string_view(), tok, 9);
  if (n < 8) throwParseError(here(), "epoch", "incomplete clock record (epoch, number of values, bias)");
  if (n > 9) throwParseError(here(), "data values", "more than two values on the first line");
  CalendarTime c;
  c.year = intToken(tok[0], here(), "epoch year", 1980, 2200);
  c.month = intToken(tok[1], here(), "epoch month", 1, 12);
  c.day = intToken(tok[2], here(), "epoch day", 1, 31);
  c.hour = intToken(tok[3], here(), "epoch hour", 0, 23);
  c.minute = intToken(tok[4], here(), "epoch minute", 0, 59);
  // F10.6 seconds: finer digits are rounded away (the epochs compared and written are the ones the
  // format can hold).
  c.second = std::round(parseFiniteDouble(tok[5], here(), "epoch second") * 1e6) * 1e-6;
  if (!isValidCalendar(c)) throwParseError(here(), "epoch", "invalid date/time");
  const int count = intToken(tok[6], here(), "number of data values", 1, kMaxValues);
  const std::size_t onFirst = static_cast<std::size_t>(std::min(count, 2));
  if (n - 7 != onFirst) {
    throwParseError(here(), "data values", std::to_string(count) + " values announced but " + std::to_string(n - 7) +
                                               " on the first line");
  }
  double values[kMaxValues] = {};
  for (std::size_t k = 0; k < onFirst; ++k)
    values[k] = clockValue(tok[7 + k], here(), k == 0 ? "clock bias" : "bias sigma");
  if (count > 2) {
    if (!in_.next(line_)) throwParseError(here(), "data values", "unexpected end of file in a continuation line");
    std::string_view more[5];
    const std::size_t m = tokens(line_, more, 4);
    if (m != static_cast<std::size_t>(count - 2)) {
      throwParseError(here(), "data values", std::to_string(count - 2) + " values expected on the continuation line");
    }
    for (std::size_t k = 0; k < m; ++k) values[2 + k] = clockValue(more[k], here(), "data values");
  }
  if (!sat) {
    ++d_.skippedRecords;
    return;
  }
  const auto id = SatId::parse(name);
  if (!id) throwParseError(here(), "satellite", "unknown satellite '" + std::string(name) + "'");
  if (count >= 2 && values[1] < 0.0) throwParseError(here(), "bias sigma", "negative sigma");
  ClockRecord r;
  r.time = productTimeToGpst(c, d_.timeSystem);
  r.bias = values[0];
  r.sigma = count >= 2 ? values[1] : 0.0;
  auto it = std::find_if(d_.satellites.begin(), d_.satellites.end(), [&](const auto& p) { return p.first == *id; });
  if (it == d_.satellites.end()) {
    d_.satellites.push_back({*id, {}});
    lines_.emplace_back();
    it = d_.satellites.end() - 1;
  }
  it->second.push_back(r);
  lines_[static_cast<std::size_t>(it - d_.satellites.begin())].push_back(here().line);
}

void ClockReader::finish() {
  for (std::size_t s = 0; s < d_.satellites.size(); ++s) {
    auto& recs = d_.satellites[s].second;
    const auto& lines = lines_[s];
    std::vector<std::size_t> order(recs.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return recs[a].time < recs[b].time; });
    std::vector<ClockRecord> sorted;
    sorted.reserve(recs.size());
    for (std::size_t k = 0; k < order.size(); ++k) {
      if (k > 0 && recs[order[k]].time == recs[order[k - 1]].time) {
        throwParseError({in_.name(), std::max(lines[order[k]], lines[order[k - 1]])}, "epoch",
                        "duplicate clock record of " + d_.satellites[s].first.str() + " at " +
                            recs[order[k]].time.toString(6));
      }
      sorted.push_back(recs[order[k]]);
    }
    recs = std::move(sorted);
  }
}

ClockData ClockReader::run() {
  readHeader();
  while (in_.next(line_)) {
    if (trim(line_).empty()) continue;
    readRecord();
  }
  finish();
  return std::move(d_);
}

}  // namespace

const std::vector<ClockRecord>* ClockData::find(SatId sat) const {
  for (const auto& [s, recs] : satellites) {
    if (s == sat) return &recs;
  }
  return nullptr;
}

ClockData parseRinexClock(std::string_view text, const std::string& name) {
  LineReader in(text, name);
  return ClockReader(in).run();
}

ClockData readRinexClock(const std::string& path) {
  LineReader in(path);
  return ClockReader(in).run();
}

void writeRinexClock(std::ostream& out, const ClockData& data) {
  const bool v304 = data.version >= 3.04 - 1e-9;
  const std::string ts = isProductTimeSystem(data.timeSystem) ? data.timeSystem : "GPS";
  char sys = 'M';
  if (!data.satellites.empty() && std::all_of(data.satellites.begin(), data.satellites.end(), [&](const auto& p) {
        return p.first.system == data.satellites.front().first.system;
      })) {
    sys = systemLetter(data.satellites.front().first.system);
  }
  auto label = [&](std::string body, const char* text) {
    body.resize(60, ' ');
    out << body << text << '\n';
  };
  char buf[128];
  std::snprintf(buf, sizeof buf, "%9.2f           C                   %c", v304 ? 3.04 : 3.00, sys);
  label(buf, "RINEX VERSION / TYPE");
  label("gvins", "PGM / RUN BY / DATE");
  label("   " + ts, "TIME SYSTEM ID");
  label("     1    AS", "# / TYPES OF DATA");
  std::snprintf(buf, sizeof buf, "%6zu", data.satellites.size());
  label(buf, "# OF SOLN SATS");
  for (std::size_t i = 0; i < data.satellites.size(); i += 15) {
    std::string s;
    for (std::size_t k = i; k < std::min(i + 15, data.satellites.size()); ++k) s += data.satellites[k].first.str() + " ";
    label(s, "PRN LIST");
  }
  label("", "END OF HEADER");
  const int nameWidth = v304 ? 9 : 4;
  // Records in time order, satellites in their listed order within an epoch (as the format's
  // examples show).
  std::vector<std::pair<std::size_t, std::size_t>> order;  // (satellite, record)
  for (std::size_t s = 0; s < data.satellites.size(); ++s) {
    for (std::size_t k = 0; k < data.satellites[s].second.size(); ++k) order.emplace_back(s, k);
  }
  auto at = [&](const std::pair<std::size_t, std::size_t>& i) -> const ClockRecord& {
    return data.satellites[i.first].second[i.second];
  };
  std::stable_sort(order.begin(), order.end(), [&](const auto& a, const auto& b) { return at(a).time < at(b).time; });
  for (const auto& i : order) {
    const std::string id = data.satellites[i.first].first.str();
    const ClockRecord& r = at(i);
    // Round to the microsecond of the F10.6 seconds field before splitting the calendar.
    const double frac = r.time.fraction();
    const CalendarTime c = gpstToProductTime(r.time + (std::round(frac * 1e6) * 1e-6 - frac), ts);
    const double bias = std::isfinite(r.bias) ? r.bias : 0.0;
    const bool sigma = std::isfinite(r.sigma) && r.sigma > 0.0;
    std::snprintf(buf, sizeof buf, "AS %-*s %4d %02d %02d %02d %02d%10.6f%3d  %19.12E", nameWidth, id.c_str(), c.year,
                  c.month, c.day, c.hour, c.minute, c.second, sigma ? 2 : 1, bias);
    out << buf;
    if (sigma) {
      std::snprintf(buf, sizeof buf, " %19.12E", r.sigma);
      out << buf;
    }
    out << '\n';
  }
}

}  // namespace gvins
