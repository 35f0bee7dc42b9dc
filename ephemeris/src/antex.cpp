// ANTEX 1.3/1.4 reader.
//
// Layout from "ANTEX: The Antenna Exchange Format, Version 1.4", R. Schmid, IGS, 2010. Record
// labels are in columns 61-80; all positions below are 0-based:
//   ANTEX VERSION / SYST  F8.1 version [0,8), 12X, A1 system [20]: G R E C J S I M
//   PCV TYPE / REFANT     A1 [0]: A (absolute) or R (relative), 19X, A20 type [20,40), A20 serial
//   START OF ANTENNA .. END OF ANTENNA, with, in this order:
//     TYPE / SERIAL NO    A20 type [0,20), A20 serial (satellites: "sNN") [20,40), A10 SVN [40,50),
//                         A10 COSPAR ID [50,60)
//     METH / BY / # / DATE (not used), DAZI (2X F6.1), ZEN1 / ZEN2 / DZEN (2X 3F6.1),
//     # OF FREQUENCIES (I6), optional VALID FROM / VALID UNTIL (5I6, F13.7; GPST),
//     SINEX CODE (A10), COMMENT
//     per frequency: START OF FREQUENCY (3X A1 system, I2 band), NORTH / EAST / UP (3F10.2 mm),
//       the NOAZI row (A8 "   NOAZI", then F8.2 mm per ZEN1..ZEN2 grid point), when DAZI > 0 one
//       row per azimuth 0, DAZI, .., 360 (F8.1 azimuth, then F8.2 mm per grid point),
//       END OF FREQUENCY; optionally followed by START OF FREQ RMS .. END OF FREQ RMS (same layout).
// PCV rows carry no label and may be longer than 80 columns; they are recognised by position in a
// frequency block. Their values are read blank-separated, or from the fixed F8.2 columns when a
// value fills its whole field (e.g. "-1000.00") so that blanks do not separate them.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "gvins/base/line_reader.hpp"
#include "gvins/base/text_fields.hpp"
#include "gvins/ephemeris/antex.hpp"

namespace gvins {
namespace {

constexpr int kMaxGridPoints = 1000;     // zenith/nadir grid points per row
constexpr int kMaxAzimuthRows = 3601;    // DAZI >= 0.1 deg
constexpr long kMaxFrequencies = 99;     // # OF FREQUENCIES
constexpr std::size_t kMaxLineLength = 8 + 8 * (kMaxGridPoints + 1) + 80;  // a full-grid PCV row
constexpr double kMmToM = 1000.0;        // divisor: mm -> m

constexpr std::string_view kVersionLabel = "ANTEX VERSION / SYST";
constexpr std::string_view kPcvTypeLabel = "PCV TYPE / REFANT";
constexpr std::string_view kEndOfHeader = "END OF HEADER";
constexpr std::string_view kStartAntenna = "START OF ANTENNA";
constexpr std::string_view kEndAntenna = "END OF ANTENNA";
constexpr std::string_view kTypeSerial = "TYPE / SERIAL NO";
constexpr std::string_view kMethod = "METH / BY / # / DATE";
constexpr std::string_view kDazi = "DAZI";
constexpr std::string_view kZen = "ZEN1 / ZEN2 / DZEN";
constexpr std::string_view kNumFreq = "# OF FREQUENCIES";
constexpr std::string_view kValidFrom = "VALID FROM";
constexpr std::string_view kValidUntil = "VALID UNTIL";
constexpr std::string_view kSinex = "SINEX CODE";
constexpr std::string_view kComment = "COMMENT";
constexpr std::string_view kStartFreq = "START OF FREQUENCY";
constexpr std::string_view kEndFreq = "END OF FREQUENCY";
constexpr std::string_view kStartRms = "START OF FREQ RMS";
constexpr std::string_view kEndRms = "END OF FREQ RMS";
constexpr std::string_view kNeu = "NORTH / EAST / UP";
constexpr std::string_view kNoazi = "NOAZI";
constexpr std::string_view kAzimuthRow = "azimuth row";

constexpr std::string_view kKnownLabels[] = {
    kVersionLabel, kPcvTypeLabel, kEndOfHeader, kStartAntenna, kEndAntenna, kTypeSerial, kMethod,
    kDazi,         kZen,          kNumFreq,     kValidFrom,    kValidUntil, kSinex,      kComment,
    kStartFreq,    kEndFreq,      kStartRms,    kEndRms,       kNeu};

// The label of columns 61-80 (trailing blanks removed); empty when the line has none or it does
// not start exactly in column 61.
std::string_view labelOf(std::string_view line) {
  std::string_view s = column(line, 60, 20);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  if (s.empty() || s.front() == ' ' || s.front() == '\t') return {};
  return s;
}

bool isKnownLabel(std::string_view label) {
  return std::find(std::begin(kKnownLabels), std::end(kKnownLabels), label) != std::end(kKnownLabels);
}

std::string_view trimRight(std::string_view s) {
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

// Blank-separated tokens of `text`; stops after max + 1 tokens (so that "too many" shows).
void tokenize(std::string_view text, std::vector<std::string_view>& out, std::size_t max) {
  out.clear();
  std::size_t i = 0;
  while (out.size() <= max) {
    while (i < text.size() && (text[i] == ' ' || text[i] == '\t')) ++i;
    if (i >= text.size()) break;
    const std::size_t start = i;
    while (i < text.size() && text[i] != ' ' && text[i] != '\t') ++i;
    out.push_back(text.substr(start, i - start));
  }
}

// A number without exceptions: the short decimal form every F-format field has.
bool tryNumber(std::string_view text, double& v) {
  text = trim(text);
  return !text.empty() && text.size() < 64 && parseShortDecimal(text, v);
}

std::string describe(std::string_view line) {
  line = trim(line);
  if (line.size() > 40) return "'" + std::string(line.substr(0, 40)) + "...'";
  return "'" + std::string(line) + "'";
}

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// Whether q is a whole number up to rounding (1e-6, relative above 1).
bool nearlyWhole(double q) { return std::abs(q - std::round(q)) <= 1e-6 * std::max(1.0, std::abs(q)); }

struct FreqCode {
  System system;
  char band;
};

class AntexReader {
 public:
  explicit AntexReader(LineReader& in) : in_(in) {}
  AntexData run();

 private:
  // One antenna being read, with what its records have declared.
  struct Pending {
    AntexAntenna a;
    std::int64_t startLine = 0;
    bool haveMethod = false, haveDazi = false, haveZen = false, haveCount = false;
    bool haveSinex = false;
    bool inFrequencies = false;  // a START OF FREQUENCY / FREQ RMS was seen
    long declared = 0;
    std::size_t gridPoints = 0, azimuthRows = 0;
    std::vector<std::pair<System, char>> rms;  // FREQ RMS blocks seen
  };

  LineReader& in_;
  AntexData d_;
  std::string_view line_;
  std::vector<std::string_view> tok_;
  std::vector<double> row_;

  TextLocation here() const { return in_.location(); }
  bool next() {
    if (!in_.next(line_)) return false;
    while (!line_.empty() && line_.back() == '\r') line_.remove_suffix(1);
    return true;
  }
  void need(std::string_view field, std::string_view what) {
    if (!next()) throwParseError(here(), field, "unexpected end of file (expected " + std::string(what) + ")");
  }
  void readHeader();
  void readAntenna();
  void antennaRecord(Pending& p, std::string_view label);
  void checkComplete(const Pending& p, std::string_view at);
  FreqCode frequencyCode(std::string_view field);
  void readFrequency(Pending& p, bool rms);
  std::string_view readRow(std::size_t n, std::string_view field);
  GpsTime validity(std::string_view field);
  void numbers(std::string_view field, std::size_t n, std::size_t offset, std::size_t width, double* out);
};

// `n` numbers in columns 1-60 of a label record: blank-separated, or fixed fields of `width`
// after `offset` blank columns (e.g. 2X, 3F6.1).
void AntexReader::numbers(std::string_view field, std::size_t n, std::size_t offset, std::size_t width,
                          double* out) {
  const std::string_view body = column(line_, 0, 60);
  tokenize(body, tok_, n);
  if (tok_.size() == n) {
    for (std::size_t k = 0; k < n; ++k) out[k] = parseFiniteDouble(tok_[k], here(), field);
    return;
  }
  bool fixed = true;
  for (std::size_t k = 0; k < n && fixed; ++k) fixed = tryNumber(column(body, offset + k * width, width), out[k]);
  if (fixed && trim(column(body, 0, offset)).empty() && trim(column(body, offset + n * width, 60)).empty()) return;
  throwParseError(here(), field, "expected " + std::to_string(n) + (n == 1 ? " value" : " values") + ", found " +
                                     std::to_string(tok_.size()) + " in " + describe(body));
}

void AntexReader::readHeader() {
  if (!next()) throwParseError(here(), kVersionLabel, "empty file");
  if (labelOf(line_) != kVersionLabel) {
    throwParseError(here(), kVersionLabel, "first line is not 'ANTEX VERSION / SYST' (not an ANTEX file?)");
  }
  d_.version = parseFiniteDouble(column(line_, 0, 8), here(), kVersionLabel);
  if (d_.version < 1.0 || d_.version >= 2.0) {
    throwParseError(here(), kVersionLabel, "unsupported ANTEX version " + fmt(d_.version) + " (1.x expected)");
  }
  const std::string_view sys = column(line_, 20, 1);
  const char s = sys.empty() ? ' ' : sys[0];
  if (s != 'M' && !systemFromLetter(s)) {
    throwParseError(here(), kVersionLabel, std::string("unknown satellite system '") + s + "' (G R E C J S I M)");
  }
  d_.system = s;
  bool havePcvType = false;
  while (true) {
    if (!next()) throwParseError(here(), kEndOfHeader, "missing 'END OF HEADER'");
    const std::string_view label = labelOf(line_);
    if (label == kEndOfHeader) break;
    if (label == kPcvTypeLabel) {
      if (havePcvType) throwParseError(here(), kPcvTypeLabel, "duplicate record");
      const std::string_view t = column(line_, 0, 1);
      if (t != "A" && t != "R") throwParseError(here(), kPcvTypeLabel, "PCV type must be A (absolute) or R (relative)");
      d_.pcvType = t[0];
      d_.referenceAntenna = std::string(trimRight(column(line_, 20, 20)));
      havePcvType = true;
    } else if (label == kComment) {
      d_.comments.emplace_back(trimRight(column(line_, 0, 60)));
    } else if (label == kVersionLabel) {
      throwParseError(here(), kVersionLabel, "duplicate record");
    } else if (label == kStartAntenna) {
      throwParseError(here(), kEndOfHeader, "START OF ANTENNA before 'END OF HEADER'");
    }
    // Other header lines are not needed.
  }
  if (!havePcvType) throwParseError(here(), kPcvTypeLabel, "missing 'PCV TYPE / REFANT' in the header");
}

FreqCode AntexReader::frequencyCode(std::string_view field) {
  const std::string_view code = column(line_, 3, 3);
  const std::string_view prefix = column(line_, 0, 3);
  if (code.size() < 3 || !trim(prefix).empty() || !trim(column(line_, 6, 54)).empty()) {
    throwParseError(here(), field, "expected a frequency code like 'G01' in columns 4-6, found " + describe(column(line_, 0, 60)));
  }
  const auto system = systemFromLetter(code[0]);
  if (!system) throwParseError(here(), field, "unknown satellite system '" + std::string(code.substr(0, 1)) + "' (G R E C J S I)");
  const std::string_view n = code.substr(1);
  const bool digits = (n[0] == '0' || n[0] == ' ') && n[1] >= '1' && n[1] <= '9';
  if (!digits) throwParseError(here(), field, "bad frequency number '" + std::string(n) + "' (01-09)");
  return {*system, n[1]};
}

GpsTime AntexReader::validity(std::string_view field) {
  const std::string_view body = column(line_, 0, 60);
  tokenize(body, tok_, 6);
  if (tok_.size() != 6) throwParseError(here(), field, "expected year month day hour minute second, found " + describe(body));
  auto whole = [&](std::size_t k, long lo, long hi) {
    const long v = parseInt(tok_[k], here(), field);
    if (v < lo || v > hi) throwParseError(here(), field, "invalid date " + describe(body));
    return static_cast<int>(v);
  };
  CalendarTime c;
  c.year = whole(0, 1950, 2200);
  c.month = whole(1, 1, 12);
  c.day = whole(2, 1, 31);
  c.hour = whole(3, 0, 23);
  c.minute = whole(4, 0, 59);
  c.second = parseFiniteDouble(tok_[5], here(), field);
  if (!isValidCalendar(c)) throwParseError(here(), field, "invalid date " + describe(body));
  return GpsTime::fromCalendar(c);
}

// A PCV row: a lead item (NOAZI or the azimuth) and n values, into row_ (mm). Returns the lead.
std::string_view AntexReader::readRow(std::size_t n, std::string_view field) {
  row_.resize(n);
  tokenize(line_, tok_, n + 1);
  bool loose = tok_.size() == n + 1;
  for (std::size_t k = 0; k < n && loose; ++k) loose = tryNumber(tok_[k + 1], row_[k]);
  if (loose) return tok_[0];
  // Fixed columns: A8/F8.1 lead, then F8.2 values (values filling all 8 columns touch).
  bool fixed = !trim(column(line_, 0, 8)).empty();
  for (std::size_t k = 0; k < n && fixed; ++k) fixed = tryNumber(column(line_, 8 + 8 * k, 8), row_[k]);
  if (fixed && trim(column(line_, 8 + 8 * n, std::string_view::npos)).empty()) return trim(column(line_, 0, 8));
  if (tok_.size() != n + 1) {
    const std::string found = tok_.size() > n + 1 ? "more" : std::to_string(tok_.empty() ? 0 : tok_.size() - 1);
    throwParseError(here(), field, "expected " + std::to_string(n) + " values on the ZEN1..ZEN2/DZEN grid, found " + found);
  }
  // Blank-separated with the right count: a number the short form does not cover, or not a number.
  for (std::size_t k = 0; k < n; ++k) row_[k] = parseFiniteDouble(tok_[k + 1], here(), field);
  return tok_[0];
}

void AntexReader::readFrequency(Pending& p, bool rms) {
  const std::string_view startLabel = rms ? kStartRms : kStartFreq;
  const std::string_view endLabel = rms ? kEndRms : kEndFreq;
  const FreqCode code = frequencyCode(startLabel);
  const std::pair<System, char> key{code.system, code.band};
  const std::string name = std::string(1, systemLetter(code.system)) + "0" + code.band;
  AntexFrequency f;
  f.system = code.system;
  f.band = code.band;
  if (rms) {
    if (!p.a.frequency(code.system, code.band)) {
      throwParseError(here(), startLabel, "RMS block of " + name + " without a preceding frequency block");
    }
    if (std::find(p.rms.begin(), p.rms.end(), key) != p.rms.end()) {
      throwParseError(here(), startLabel, "duplicate RMS block of " + name);
    }
    p.rms.push_back(key);
  } else {
    if (p.a.frequency(code.system, code.band)) throwParseError(here(), startLabel, "duplicate frequency block " + name);
    if (static_cast<long>(p.a.frequencies.size()) >= p.declared) {
      throwParseError(here(), kNumFreq, "more frequency blocks than the " + std::to_string(p.declared) + " declared");
    }
  }

  need(kNeu, "NORTH / EAST / UP");
  if (labelOf(line_) != kNeu) throwParseError(here(), kNeu, "expected 'NORTH / EAST / UP' after " + std::string(startLabel));
  double neu[3];
  numbers(kNeu, 3, 0, 10, neu);
  f.offset = Eigen::Vector3d(neu[0], neu[1], neu[2]) / kMmToM;

  need(kNoazi, "the NOAZI row");
  if (isKnownLabel(labelOf(line_))) {
    throwParseError(here(), kNoazi, "found '" + std::string(labelOf(line_)) + "' where the NOAZI row was expected");
  }
  if (readRow(p.gridPoints, kNoazi) != kNoazi) {
    throwParseError(here(), kNoazi, "expected the NOAZI row, found " + describe(column(line_, 0, 8)));
  }
  f.noAzimuth.resize(row_.size());
  std::transform(row_.begin(), row_.end(), f.noAzimuth.begin(), [](double v) { return v / kMmToM; });

  f.byAzimuth.reserve(p.azimuthRows);
  for (std::size_t r = 0; r < p.azimuthRows; ++r) {
    const double expected = static_cast<double>(r) * p.a.dazi;
    need(kAzimuthRow, "the azimuth row " + fmt(expected));
    if (isKnownLabel(labelOf(line_))) {
      throwParseError(here(), kAzimuthRow, "found '" + std::string(labelOf(line_)) + "' after " + std::to_string(r) + " of " +
                                               std::to_string(p.azimuthRows) + " azimuth rows (DAZI " + fmt(p.a.dazi) + ")");
    }
    const std::string_view lead = readRow(p.gridPoints, kAzimuthRow);
    const double az = parseFiniteDouble(lead, here(), kAzimuthRow);
    if (std::abs(az - expected) > 0.05 + 1e-9) {
      throwParseError(here(), kAzimuthRow, "azimuth " + fmt(az) + " where " + fmt(expected) + " was expected (DAZI " +
                                               fmt(p.a.dazi) + ")");
    }
    f.byAzimuth.emplace_back(row_.size());
    std::transform(row_.begin(), row_.end(), f.byAzimuth.back().begin(), [](double v) { return v / kMmToM; });
  }

  need(endLabel, std::string(endLabel));
  const std::string_view label = labelOf(line_);
  if (label != endLabel) {
    std::string what = "expected '" + std::string(endLabel) + "', found " +
                       (label.empty() ? describe(line_) : "'" + std::string(label) + "'");
    if (p.azimuthRows == 0 && label.empty()) what += " (azimuth rows with DAZI = 0?)";
    throwParseError(here(), endLabel, what);
  }
  if (!trim(column(line_, 0, 60)).empty()) {
    const FreqCode end = frequencyCode(endLabel);
    if (end.system != code.system || end.band != code.band) {
      throwParseError(here(), endLabel, "frequency code differs from the one of " + std::string(startLabel) + " (" + name + ")");
    }
  }
  if (!rms) p.a.frequencies.push_back(std::move(f));
}

void AntexReader::checkComplete(const Pending& p, std::string_view at) {
  if (!p.haveDazi) throwParseError(here(), kDazi, "missing 'DAZI' before " + std::string(at));
  if (!p.haveZen) throwParseError(here(), kZen, "missing 'ZEN1 / ZEN2 / DZEN' before " + std::string(at));
  if (!p.haveCount) throwParseError(here(), kNumFreq, "missing '# OF FREQUENCIES' before " + std::string(at));
}

void AntexReader::antennaRecord(Pending& p, std::string_view label) {
  const bool isHeaderRecord = label == kTypeSerial || label == kMethod || label == kDazi || label == kZen ||
                              label == kNumFreq || label == kValidFrom || label == kValidUntil || label == kSinex;
  if (isHeaderRecord && p.inFrequencies) {
    throwParseError(here(), label, "'" + std::string(label) + "' after the frequency blocks");
  }
  if (label == kTypeSerial) {
    throwParseError(here(), kTypeSerial, "duplicate record");
  } else if (label == kMethod) {
    if (p.haveMethod) throwParseError(here(), kMethod, "duplicate record");
    p.haveMethod = true;
  } else if (label == kDazi) {
    if (p.haveDazi) throwParseError(here(), kDazi, "duplicate record");
    double v;
    numbers(kDazi, 1, 2, 6, &v);
    if (v < 0.0 || v > 360.0) throwParseError(here(), kDazi, "DAZI " + fmt(v) + " out of range [0, 360]");
    if (v > 0.0) {
      const double q = 360.0 / v;
      if (!nearlyWhole(q)) throwParseError(here(), kDazi, "DAZI " + fmt(v) + " does not divide 360");
      if (std::round(q) + 1 > kMaxAzimuthRows) throwParseError(here(), kDazi, "DAZI " + fmt(v) + " below 0.1 deg");
      p.azimuthRows = static_cast<std::size_t>(std::round(q)) + 1;
    }
    p.a.dazi = v;
    p.haveDazi = true;
  } else if (label == kZen) {
    if (p.haveZen) throwParseError(here(), kZen, "duplicate record");
    double z[3];
    numbers(kZen, 3, 2, 6, z);
    const double z1 = z[0], z2 = z[1], dz = z[2];
    if (z1 < 0.0 || z2 > 180.0 || !(z2 > z1)) {
      throwParseError(here(), kZen, "need 0 <= ZEN1 < ZEN2 <= 180, got " + fmt(z1) + ", " + fmt(z2));
    }
    if (!(dz > 0.0)) throwParseError(here(), kZen, "DZEN " + fmt(dz) + " must be positive");
    const double q = (z2 - z1) / dz;
    if (!nearlyWhole(q)) throwParseError(here(), kZen, "ZEN2 - ZEN1 is not a multiple of DZEN " + fmt(dz));
    if (std::round(q) + 1 > kMaxGridPoints) {
      throwParseError(here(), kZen, "grid of " + fmt(std::round(q) + 1) + " points (at most " +
                                        std::to_string(kMaxGridPoints) + ")");
    }
    p.gridPoints = static_cast<std::size_t>(std::round(q)) + 1;
    p.a.zen1 = z1;
    p.a.zen2 = z2;
    p.a.dzen = dz;
    p.haveZen = true;
  } else if (label == kNumFreq) {
    if (p.haveCount) throwParseError(here(), kNumFreq, "duplicate record");
    tokenize(column(line_, 0, 60), tok_, 1);
    if (tok_.size() != 1) throwParseError(here(), kNumFreq, "expected one number, found " + describe(column(line_, 0, 60)));
    p.declared = parseInt(tok_[0], here(), kNumFreq);
    if (p.declared < 1 || p.declared > kMaxFrequencies) {
      throwParseError(here(), kNumFreq, std::to_string(p.declared) + " out of range [1, " + std::to_string(kMaxFrequencies) + "]");
    }
    p.haveCount = true;
  } else if (label == kValidFrom || label == kValidUntil) {
    const bool from = label == kValidFrom;
    auto& slot = from ? p.a.validFrom : p.a.validUntil;
    if (slot) throwParseError(here(), label, "duplicate record");
    slot = validity(label);
    if (p.a.validFrom && p.a.validUntil && !(*p.a.validFrom < *p.a.validUntil)) {
      throwParseError(here(), label, "VALID UNTIL " + p.a.validUntil->toString(0) + " is not after VALID FROM " +
                                         p.a.validFrom->toString(0));
    }
  } else if (label == kSinex) {
    if (p.haveSinex) throwParseError(here(), kSinex, "duplicate record");
    p.a.sinexCode = std::string(trim(column(line_, 0, 10)));
    p.haveSinex = true;
  } else if (label == kComment) {
    // Antenna comments are not kept.
  } else if (label == kStartFreq || label == kStartRms) {
    checkComplete(p, label);
    p.inFrequencies = true;
    readFrequency(p, label == kStartRms);
  } else if (label == kNeu || label == kEndFreq || label == kEndRms) {
    throwParseError(here(), label, "'" + std::string(label) + "' outside a frequency block");
  } else if (label == kStartAntenna) {
    throwParseError(here(), kStartAntenna, "START OF ANTENNA inside the antenna of line " + std::to_string(p.startLine) +
                                               " (missing END OF ANTENNA)");
  } else if (label.empty()) {
    throwParseError(here(), "antenna record", "line without a label inside an antenna: " + describe(line_));
  } else {
    throwParseError(here(), "antenna record", "unknown record '" + std::string(label) + "' inside an antenna");
  }
}

void AntexReader::readAntenna() {
  Pending p;
  p.startLine = here().line;
  need(kTypeSerial, "TYPE / SERIAL NO");
  if (labelOf(line_) != kTypeSerial) {
    throwParseError(here(), kTypeSerial, "expected 'TYPE / SERIAL NO' after START OF ANTENNA");
  }
  p.a.type = std::string(trimRight(column(line_, 0, 20)));
  if (trim(p.a.type).empty()) throwParseError(here(), kTypeSerial, "empty antenna type");
  p.a.serial = std::string(trim(column(line_, 20, 20)));
  p.a.svn = std::string(trim(column(line_, 40, 10)));
  p.a.cospar = std::string(trim(column(line_, 50, 10)));
  // Satellite antennas name the satellite ("G01", "E11"); a receiver antenna's serial number (or a
  // blank for all antennas of the type) never starts with a system letter followed by 1-2 digits.
  if (!p.a.serial.empty() && std::isalpha(static_cast<unsigned char>(p.a.serial[0]))) {
    p.a.satellite = SatId::parse(p.a.serial);
  }
  while (true) {
    if (!next()) {
      throwParseError(here(), kEndAntenna, "unexpected end of file inside the antenna of line " + std::to_string(p.startLine) +
                                               " (missing END OF ANTENNA)");
    }
    const std::string_view label = labelOf(line_);
    if (label.empty() && trim(line_).empty()) continue;
    if (label == kEndAntenna) break;
    antennaRecord(p, label);
  }
  checkComplete(p, kEndAntenna);
  if (static_cast<long>(p.a.frequencies.size()) != p.declared) {
    throwParseError(here(), kNumFreq, std::to_string(p.a.frequencies.size()) + " frequency blocks but " +
                                          std::to_string(p.declared) + " declared");
  }
  d_.antennas.push_back(std::move(p.a));
}

AntexData AntexReader::run() {
  readHeader();
  while (next()) {
    const std::string_view label = labelOf(line_);
    if (label.empty() && trim(line_).empty()) continue;
    if (label != kStartAntenna) {
      throwParseError(here(), kStartAntenna, (label.empty() ? describe(line_) : "'" + std::string(label) + "'") +
                                                 " outside an antenna (expected START OF ANTENNA)");
    }
    readAntenna();
  }
  return std::move(d_);
}

}  // namespace

const AntexFrequency* AntexAntenna::frequency(System system, char band) const {
  for (const auto& f : frequencies) {
    if (f.system == system && f.band == band) return &f;
  }
  return nullptr;
}

bool AntexAntenna::validAt(const GpsTime& t) const {
  return (!validFrom || *validFrom <= t) && (!validUntil || t < *validUntil);
}

const AntexAntenna* AntexData::satellite(SatId sat, const GpsTime& t) const {
  const AntexAntenna* best = nullptr;
  for (const auto& a : antennas) {
    if (!a.satellite || !(*a.satellite == sat) || !a.validAt(t)) continue;
    // An open VALID FROM counts as the earliest.
    if (!best || (a.validFrom && (!best->validFrom || *best->validFrom < *a.validFrom))) best = &a;
  }
  return best;
}

const AntexAntenna* AntexData::receiver(std::string_view typeAndRadome) const {
  // Type-wide calibrations (blank serial) come before individual ones of the same type.
  auto find = [&](std::string_view type) -> const AntexAntenna* {
    const AntexAntenna* any = nullptr;
    for (const auto& a : antennas) {
      if (a.isSatellite() || a.type != type) continue;
      if (a.serial.empty()) return &a;
      if (!any) any = &a;
    }
    return any;
  };
  const std::string_view query = trimRight(typeAndRadome);
  if (query.empty()) return nullptr;
  if (const AntexAntenna* a = find(query)) return a;
  // Columns 1-16 antenna, 17-20 radome: retry with radome NONE.
  if (trim(column(query, 16, 4)) == "NONE") return nullptr;
  std::string none(trimRight(column(query, 0, 16)));
  none.resize(16, ' ');
  none += "NONE";
  return find(none);
}

AntexData parseAntex(std::string_view text, const std::string& name) {
  LineReader in(text, name, kMaxLineLength);
  return AntexReader(in).run();
}

AntexData readAntex(const std::string& path) {
  LineReader in(path, kMaxLineLength);
  return AntexReader(in).run();
}


namespace {

/// One 80-column record: `body` padded (or cut) to 60 columns, then the label.
void record(std::ostream& out, const std::string& body, const char* label) {
  std::string b = body.substr(0, 60);
  b.resize(60, ' ');
  out << b << label << '\n';
}

std::string validityText(const GpsTime& t) {
  const CalendarTime c = t.toCalendar();
  char buf[64];
  std::snprintf(buf, sizeof buf, "%6d%6d%6d%6d%6d%13.7f", c.year, c.month, c.day, c.hour, c.minute, c.second);
  return buf;
}

void writeRow(std::ostream& out, const char* head, const std::vector<double>& values) {
  out << head;
  char buf[32];
  for (double v : values) {
    std::snprintf(buf, sizeof buf, "%8.2f", v * 1000.0);
    out << buf;
  }
  out << '\n';
}

}  // namespace

void writeAntex(std::ostream& out, const AntexData& data) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "%8.1f%12s%c", data.version, "", data.system);
  record(out, buf, "ANTEX VERSION / SYST");
  std::snprintf(buf, sizeof buf, "%c%19s%-20s", data.pcvType, "", data.referenceAntenna.c_str());
  record(out, buf, "PCV TYPE / REFANT");
  for (const std::string& c : data.comments) record(out, c, "COMMENT");
  record(out, "", "END OF HEADER");
  for (const AntexAntenna& a : data.antennas) {
    record(out, "", "START OF ANTENNA");
    std::snprintf(buf, sizeof buf, "%-20.20s%-20.20s%-10.10s%-10.10s", a.type.c_str(), a.serial.c_str(), a.svn.c_str(),
                  a.cospar.c_str());
    record(out, buf, "TYPE / SERIAL NO");
    std::snprintf(buf, sizeof buf, "  %6.1f", a.dazi);
    record(out, buf, "DAZI");
    std::snprintf(buf, sizeof buf, "  %6.1f%6.1f%6.1f", a.zen1, a.zen2, a.dzen);
    record(out, buf, "ZEN1 / ZEN2 / DZEN");
    std::snprintf(buf, sizeof buf, "%6zu", a.frequencies.size());
    record(out, buf, "# OF FREQUENCIES");
    if (a.validFrom) record(out, validityText(*a.validFrom), "VALID FROM");
    if (a.validUntil) record(out, validityText(*a.validUntil), "VALID UNTIL");
    if (!a.sinexCode.empty()) record(out, a.sinexCode, "SINEX CODE");
    for (const AntexFrequency& f : a.frequencies) {
      std::snprintf(buf, sizeof buf, "   %c%02d", systemLetter(f.system), f.band - '0');
      const std::string code = buf;
      record(out, code, "START OF FREQUENCY");
      std::snprintf(buf, sizeof buf, "%10.2f%10.2f%10.2f", f.offset.x() * 1000.0, f.offset.y() * 1000.0,
                    f.offset.z() * 1000.0);
      record(out, buf, "NORTH / EAST / UP");
      writeRow(out, "   NOAZI", f.noAzimuth);
      for (std::size_t k = 0; k < f.byAzimuth.size(); ++k) {
        std::snprintf(buf, sizeof buf, "%8.1f", static_cast<double>(k) * a.dazi);
        writeRow(out, buf, f.byAzimuth[k]);
      }
      record(out, code, "END OF FREQUENCY");
    }
    record(out, "", "END OF ANTENNA");
  }
}

}  // namespace gvins
