// Bias-SINEX 1.00 reader.
//
// Layout from "SINEX BIAS - Solution (Software/technique) INdependent EXchange Format for GNSS
// Biases, Version 1.00", S. Schaer, IGS, 2016:
//   "%=BIA 1.00 AGC YYYY:DDD:SSSSS AGC YYYY:DDD:SSSSS YYYY:DDD:SSSSS C NNNNNNNN" first line (only
//   "%=BIA", the version and the agency in columns 12-14 are read), "*" comment lines, blocks
//   "+NAME" .. "-NAME", "%=ENDBIA" last line. Of the blocks only BIAS/DESCRIPTION (keyword
//   TIME_SYSTEM) and BIAS/SOLUTION are read; the others are skipped (but must be closed).
//   BIAS/SOLUTION data lines, 1-based columns:
//     2-5 BIAS (OSB DSB ISB), 7-10 SVN, 12-14 PRN, 16-24 STATION, 26-29 OBS1, 31-34 OBS2,
//     36-49 BIAS_START, 51-64 BIAS_END (YYYY:DDD:SSSSS; 0000:000:00000 = open end), 66-69 UNIT,
//     71-91 ESTIMATED_VALUE, 93-103 STD_DEV, optional 105-125 ESTIMATED_SLOPE, 127-137 STD_DEV.
//   UNIT, the value and the standard deviations are read blank-separated from column 66 on, so
//   that values written with fewer decimals or a few columns off their field are accepted; a
//   token starting in column 105 or later belongs to the slope (read, checked, not kept).
// Choices: blank lines are skipped anywhere; a block may appear more than once (a second
// +BIAS/SOLUTION adds its entries); a TIME_SYSTEM that changes after bias lines were read is an
// error (their times were already converted); the seconds of day may be 86400 (= next day 0 s);
// the end of an interval must be after its start; anything but comments after %=ENDBIA is an
// error.
#include <cctype>
#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "gvins/base/line_reader.hpp"
#include "gvins/base/text_fields.hpp"
#include "gvins/ephemeris/bias_sinex.hpp"
#include "product_time_scale.hpp"

namespace gvins {
namespace {

constexpr std::size_t kMaxLineLength = 512;  // data lines are 137 columns at most
constexpr double kNsToS = 1e-9;

constexpr std::string_view kHeader = "%=BIA";
constexpr std::string_view kEnd = "%=ENDBIA";
constexpr std::string_view kDescription = "BIAS/DESCRIPTION";
constexpr std::string_view kSolution = "BIAS/SOLUTION";
constexpr std::string_view kTimeSystem = "TIME_SYSTEM";
constexpr std::string_view kBias = "BIAS";
constexpr std::string_view kSvn = "SVN";
constexpr std::string_view kPrn = "PRN";
constexpr std::string_view kStation = "STATION";
constexpr std::string_view kObs1 = "OBS1";
constexpr std::string_view kObs2 = "OBS2";
constexpr std::string_view kStart = "BIAS_START";
constexpr std::string_view kEndTime = "BIAS_END";
constexpr std::string_view kUnit = "UNIT";
constexpr std::string_view kValue = "ESTIMATED_VALUE";
constexpr std::string_view kStdDev = "STD_DEV";
constexpr std::string_view kSlope = "ESTIMATED_SLOPE";

// A fixed field of a BIAS/SOLUTION line: 0-based start, width, name.
struct Field {
  std::size_t pos, len;
  std::string_view name;
};
constexpr Field kFields[] = {{1, 4, kBias},     {6, 4, kSvn},      {11, 3, kPrn},    {15, 9, kStation},
                             {25, 4, kObs1},    {30, 4, kObs2},    {35, 14, kStart}, {50, 14, kEndTime}};
constexpr std::size_t kValuesFrom = 65;  // UNIT onwards, blank-separated
constexpr std::size_t kSlopeFrom = 104;  // column 105: the ESTIMATED_SLOPE field

bool startsWith(std::string_view s, std::string_view p) { return s.substr(0, p.size()) == p; }

std::string_view trimRight(std::string_view s) {
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

bool isBlank(char c) { return c == ' ' || c == '\t'; }
bool isDigit(char c) { return c >= '0' && c <= '9'; }

std::string describe(std::string_view s) {
  s = trim(s);
  std::string out;
  for (char c : s.substr(0, 40)) out += (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) ? '?' : c;
  return "'" + out + (s.size() > 40 ? "...'" : "'");
}

struct Token {
  std::string_view text;
  std::size_t pos;  // 0-based column in the line
};

// Blank-separated tokens of line[from..); stops after max + 1 tokens (so that "too many" shows).
void tokenize(std::string_view line, std::size_t from, std::vector<Token>& out, std::size_t max) {
  out.clear();
  std::size_t i = from;
  while (out.size() <= max) {
    while (i < line.size() && isBlank(line[i])) ++i;
    if (i >= line.size()) break;
    const std::size_t start = i;
    while (i < line.size() && !isBlank(line[i])) ++i;
    out.push_back({line.substr(start, i - start), start});
  }
}

// The product time scale (product_time_scale.hpp) of a TIME_SYSTEM value, or empty if unknown.
std::string_view productScale(std::string_view ts) {
  if (ts == "G") return "GPS";
  if (ts == "E") return "GAL";
  if (ts == "C") return "BDT";
  if (ts == "R") return "GLO";
  if (ts == "J") return "QZS";
  if (ts == "I") return "IRN";
  if (ts == "UTC") return "UTC";
  if (ts == "TAI") return "TAI";
  return {};
}

bool validAt(const BiasEntry& e, const GpsTime& t) { return e.start <= t && (e.openEnd || t < e.end); }

class BiasSinexReader {
 public:
  explicit BiasSinexReader(LineReader& in) : in_(in) {}
  BiasSinexData run();

 private:
  LineReader& in_;
  BiasSinexData d_;
  std::string_view line_;
  std::vector<Token> tok_;
  std::string block_;          // the open block, empty outside blocks
  std::int64_t blockLine_ = 0;  // its + line
  std::string_view scale_ = "GPS";

  TextLocation here() const { return in_.location(); }
  bool next() {
    if (!in_.next(line_)) return false;
    while (!line_.empty() && line_.back() == '\r') line_.remove_suffix(1);
    return true;
  }
  void readHeader();
  void openBlock();
  void closeBlock();
  void descriptionLine();
  void solutionLine();
  bool time(std::string_view field, std::size_t pos, bool mayBeOpen, GpsTime& t);
  ObsCode observable(std::string_view field, std::string_view text, char& type);
};

void BiasSinexReader::readHeader() {
  if (!next()) throwParseError(here(), kHeader, "empty file");
  if (!startsWith(line_, kHeader)) throwParseError(here(), kHeader, "first line does not start with '%=BIA' (not a Bias-SINEX file?)");
  tokenize(line_, kHeader.size(), tok_, 1);
  if (tok_.empty()) throwParseError(here(), kHeader, "missing format version");
  double version = 0.0;
  if (!parseShortDecimal(tok_[0].text, version) || version < 1.0 || version >= 2.0) {
    throwParseError(here(), kHeader, "unsupported format version " + describe(tok_[0].text) + " (1.xx expected)");
  }
  d_.agency = std::string(trim(column(line_, 11, 3)));
}

void BiasSinexReader::openBlock() {
  const std::string_view name = trimRight(line_.substr(1));
  if (name.empty() || name.front() == ' ') throwParseError(here(), "block", "'+' without a block name");
  if (!block_.empty()) {
    throwParseError(here(), block_, "+" + std::string(name) + " inside the block opened on line " + std::to_string(blockLine_) +
                                        " (missing -" + block_ + ")");
  }
  block_ = std::string(name);
  blockLine_ = here().line;
}

void BiasSinexReader::closeBlock() {
  const std::string_view name = trimRight(line_.substr(1));
  if (block_.empty()) {
    throwParseError(here(), name.empty() ? std::string_view("block") : name,
                    "-" + std::string(name) + " without a preceding +" + std::string(name));
  }
  if (name != block_) {
    throwParseError(here(), block_, "-" + std::string(name) + " closes the block +" + block_ + " of line " +
                                        std::to_string(blockLine_));
  }
  block_.clear();
}

void BiasSinexReader::descriptionLine() {
  if (!isBlank(line_.front())) throwParseError(here(), kDescription, "expected a keyword line, found " + describe(line_));
  tokenize(line_, 0, tok_, 2);
  if (tok_.empty() || tok_[0].text != kTimeSystem) return;  // other keywords are not needed
  if (tok_.size() < 2) throwParseError(here(), kTimeSystem, "missing value");
  const std::string_view ts = tok_[1].text;
  const std::string_view scale = productScale(ts);
  if (scale.empty()) throwParseError(here(), kTimeSystem, "unknown time system " + describe(ts) + " (G E C R J I UTC TAI)");
  if (!d_.entries.empty() && ts != d_.timeSystem) {
    throwParseError(here(), kTimeSystem, "time system " + std::string(ts) + " after bias lines read in " + d_.timeSystem);
  }
  d_.timeSystem = std::string(ts);
  scale_ = scale;
}

// YYYY:DDD:SSSSS in the file's time system to GPST. Returns false for 0000:000:00000 when
// `mayBeOpen`.
bool BiasSinexReader::time(std::string_view field, std::size_t pos, bool mayBeOpen, GpsTime& t) {
  const std::string_view text = trim(column(line_, pos, 14));
  if (text.empty()) throwParseError(here(), field, "missing time (YYYY:DDD:SSSSS)");
  std::string_view part[3];
  std::size_t n = 0, from = 0;
  bool ok = true;
  for (std::size_t i = 0; i <= text.size() && ok; ++i) {
    if (i == text.size() || text[i] == ':') {
      ok = n < 3;
      if (ok) part[n++] = text.substr(from, i - from);
      from = i + 1;
    } else {
      ok = isDigit(text[i]);
    }
  }
  ok = ok && n == 3 && !part[0].empty() && !part[1].empty() && !part[2].empty() && part[1].size() <= 3 &&
       part[2].size() <= 5;
  if (!ok) throwParseError(here(), field, "bad time " + describe(text) + " (YYYY:DDD:SSSSS)");
  if (part[0].size() != 4) throwParseError(here(), field, "year of " + describe(text) + " is not 4 digits (Bias-SINEX 1.00)");
  auto value = [](std::string_view s) {
    long v = 0;
    for (char c : s) v = v * 10 + (c - '0');
    return v;
  };
  const long year = value(part[0]), doy = value(part[1]), sod = value(part[2]);
  if (year == 0 && doy == 0 && sod == 0) {
    if (!mayBeOpen) throwParseError(here(), field, "start time 0000:000:00000");
    return false;
  }
  if (year < 1980 || year > 2200) throwParseError(here(), field, "year " + std::to_string(year) + " out of range [1980, 2200]");
  const int daysInYear = dayOfYear(static_cast<int>(year), 12, 31);
  if (doy < 1 || doy > daysInYear) {
    throwParseError(here(), field, "day of year " + std::to_string(doy) + " out of range [1, " + std::to_string(daysInYear) + "]");
  }
  if (sod > 86400) throwParseError(here(), field, "second of day " + std::to_string(sod) + " out of range [0, 86400]");
  const std::int64_t days = daysFromCivil(static_cast<int>(year), 1, 1) + (doy - 1) + (sod == 86400 ? 1 : 0);
  const long s = sod % 86400;
  CalendarTime c;
  civilFromDays(days, c.year, c.month, c.day);
  c.hour = static_cast<int>(s / 3600);
  c.minute = static_cast<int>(s % 3600 / 60);
  c.second = static_cast<double>(s % 60);
  t = productTimeToGpst(c, scale_);
  return true;
}

// A RINEX 3 observable "C1W" / "L5Q": type letter into `type`, the code returned.
ObsCode BiasSinexReader::observable(std::string_view field, std::string_view text, char& type) {
  text = trim(text);
  if (text.empty()) throwParseError(here(), field, "missing observable");
  std::optional<ObsCode> code;
  if (text.size() == 3 && (text[0] == 'C' || text[0] == 'L')) code = ObsCode::parse(text.substr(1));
  if (!code) throwParseError(here(), field, "bad observable " + describe(text) + " (C or L, band digit, attribute, e.g. C1W)");
  type = text[0];
  return *code;
}

void BiasSinexReader::solutionLine() {
  if (!isBlank(line_.front())) throwParseError(here(), kBias, "expected a bias line starting with a blank, found " + describe(line_));
  // The columns between the fixed fields are blank; a character there means a shifted field.
  for (const Field& f : kFields) {
    const std::size_t gap = f.pos + f.len;
    if (gap < line_.size() && !isBlank(line_[gap])) {
      throwParseError(here(), f.name, "column " + std::to_string(gap + 1) + " after " + std::string(f.name) + " (columns " +
                                          std::to_string(f.pos + 1) + "-" + std::to_string(gap) +
                                          ") is not blank: field shifted?");
    }
  }
  BiasEntry e;
  const std::string_view type = trim(column(line_, 1, 4));
  if (type == "OSB") {
    e.type = BiasType::kOsb;
  } else if (type == "DSB") {
    e.type = BiasType::kDsb;
  } else if (type == "ISB") {
    e.type = BiasType::kIsb;
  } else {
    throwParseError(here(), kBias, "unknown bias type " + describe(type) + " (OSB DSB ISB)");
  }
  e.svn = std::string(trim(column(line_, 6, 4)));
  e.station = std::string(trim(column(line_, 15, 9)));
  const std::string_view prn = trim(column(line_, 11, 3));
  if (prn.size() == 1 && systemFromLetter(prn[0]) && !e.station.empty()) {
    // A station bias for a whole system names only the system letter.
  } else if (!prn.empty()) {
    e.satellite = SatId::parse(prn);
    if (!e.satellite || !std::isalpha(static_cast<unsigned char>(prn[0]))) {
      throwParseError(here(), kPrn, "bad satellite " + describe(prn) + " (e.g. G01)");
    }
  } else if (e.station.empty()) {
    throwParseError(here(), kPrn, "neither PRN nor STATION given");
  }

  char type1 = 'C';
  e.obs1 = observable(kObs1, column(line_, 25, 4), type1);
  e.phase = type1 == 'L';
  const std::string_view obs2 = trim(column(line_, 30, 4));
  if (e.type == BiasType::kOsb) {
    if (!obs2.empty()) throwParseError(here(), kObs2, "OBS2 " + describe(obs2) + " given for an OSB");
  } else if (!obs2.empty() || e.type == BiasType::kDsb) {
    char type2 = 'C';
    e.obs2 = observable(kObs2, obs2, type2);
    if (type2 != type1) throwParseError(here(), kObs2, "OBS2 " + describe(obs2) + " is not of the type of OBS1");
  }

  time(kStart, 35, false, e.start);
  e.openEnd = !time(kEndTime, 50, true, e.end);
  if (!e.openEnd && !(e.start < e.end)) {
    throwParseError(here(), kEndTime, "end " + e.end.toString(0) + " is not after start " + e.start.toString(0));
  }

  tokenize(line_, kValuesFrom, tok_, 5);
  if (tok_.empty()) throwParseError(here(), kUnit, "missing unit (ns or cyc)");
  if (tok_.size() > 5) throwParseError(here(), kValue, "too many values after the unit");
  const std::string_view unit = tok_[0].text;
  if (unit != "ns" && unit != "cyc") throwParseError(here(), kUnit, "unknown unit " + describe(unit) + " (ns or cyc)");
  if (unit == "cyc" && !e.phase) throwParseError(here(), kUnit, "unit cyc for the code observable " + describe(column(line_, 25, 4)));
  e.unit = std::string(unit);
  const double scale = unit == "ns" ? kNsToS : 1.0;
  if (tok_.size() < 2) throwParseError(here(), kValue, "missing value");
  e.value = parseFiniteDouble(tok_[1].text, here(), kValue) * scale;
  std::size_t k = 2;
  if (k < tok_.size() && tok_[k].pos < kSlopeFrom) {
    const double s = parseFiniteDouble(tok_[k].text, here(), kStdDev);
    if (s < 0.0) throwParseError(here(), kStdDev, "negative standard deviation " + describe(tok_[k].text));
    e.sigma = s * scale;
    ++k;
  }
  if (tok_.size() - k > 2) throwParseError(here(), kValue, "too many values after the unit");
  for (std::string_view field = kSlope; k < tok_.size(); ++k, field = kStdDev) {
    if (tok_[k].pos < kSlopeFrom) throwParseError(here(), field, "value " + describe(tok_[k].text) + " before column 105");
    parseFiniteDouble(tok_[k].text, here(), field);  // the slope is not kept
  }
  d_.entries.push_back(std::move(e));
}

BiasSinexData BiasSinexReader::run() {
  readHeader();
  bool ended = false;
  while (next()) {
    if (trim(line_).empty() || line_.front() == '*') continue;
    if (ended) throwParseError(here(), kEnd, "content after %=ENDBIA: " + describe(line_));
    const char c = line_.front();
    if (c == '%') {
      if (!startsWith(line_, kEnd)) throwParseError(here(), kHeader, "unexpected line " + describe(line_));
      if (!block_.empty()) {
        throwParseError(here(), block_, "%=ENDBIA inside the block of line " + std::to_string(blockLine_) + " (missing -" +
                                            block_ + ")");
      }
      ended = true;
    } else if (c == '+') {
      openBlock();
    } else if (c == '-') {
      closeBlock();
    } else if (block_.empty()) {
      throwParseError(here(), kSolution, "data line outside a block: " + describe(line_));
    } else if (block_ == kSolution) {
      solutionLine();
    } else if (block_ == kDescription) {
      descriptionLine();
    }
    // Lines of other blocks are not needed.
  }
  if (!block_.empty()) {
    throwParseError(here(), block_, "end of file inside the block of line " + std::to_string(blockLine_) + " (missing -" +
                                        block_ + ")");
  }
  if (!ended) throwParseError(here(), kEnd, "missing %=ENDBIA (file truncated?)");
  return std::move(d_);
}

}  // namespace

std::optional<double> BiasSinexData::codeOsb(SatId sat, ObsCode code, const GpsTime& t) const {
  std::optional<double> value;
  for (const BiasEntry& e : entries) {
    if (e.type == BiasType::kOsb && !e.phase && e.station.empty() && e.satellite && *e.satellite == sat &&
        e.obs1 == code && validAt(e, t)) {
      value = e.value;
    }
  }
  return value;
}

std::optional<double> BiasSinexData::codeDsb(SatId sat, ObsCode obs1, ObsCode obs2, const GpsTime& t) const {
  std::optional<double> value;
  for (const BiasEntry& e : entries) {
    if (e.type != BiasType::kDsb || e.phase || !e.station.empty() || !e.satellite || !(*e.satellite == sat) || !e.obs2 ||
        !validAt(e, t)) {
      continue;
    }
    if (e.obs1 == obs1 && *e.obs2 == obs2) {
      value = e.value;
    } else if (e.obs1 == obs2 && *e.obs2 == obs1) {
      value = -e.value;
    }
  }
  if (value) return value;
  const auto a = codeOsb(sat, obs1, t);
  const auto b = codeOsb(sat, obs2, t);
  if (a && b) return *a - *b;
  return std::nullopt;
}

BiasSinexData parseBiasSinex(std::string_view text, const std::string& name) {
  LineReader in(text, name, kMaxLineLength);
  return BiasSinexReader(in).run();
}

BiasSinexData readBiasSinex(const std::string& path) {
  LineReader in(path, kMaxLineLength);
  return BiasSinexReader(in).run();
}

}  // namespace gvins
