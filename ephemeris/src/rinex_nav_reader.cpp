// RINEX navigation reader: versions 2.10/2.11 (GPS "N", GLONASS "G", SBAS "H" and other
// single-system files), 3.0x (single-system and mixed) and 4.0x (EPH/STO/ION/EOP records).
//
// Format references: RINEX 2.10/2.11 (Gurtner & Estey) appendix tables for GPS and GLONASS
// navigation files; RINEX 3.04 (IGS/RTCM 2018) appendix tables for the navigation header and the
// GPS, Galileo (table A8, data sources), QZSS, BDS and GLONASS records; RINEX 3.05 (GLONASS fourth
// orbit line); RINEX 4.00 (2021) EPH/STO/ION/EOP navigation records.
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "gvins/base/constants.hpp"
#include "gvins/base/line_reader.hpp"
#include "gvins/base/text_fields.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"

namespace gvins {
namespace {

constexpr double kWeek = 604800.0;
constexpr double kDay = 86400.0;

// ---- numbers ---------------------------------------------------------------------------------

// A RINEX floating-point field: Fortran 'D' exponents, missing leading zeros (" .1118D-07"),
// Fortran's letterless three-digit exponents (".123456789012-100") and blanks (= 0) accepted.
double navNumber(std::string_view text, const TextLocation& where, std::string_view field) {
  text = trim(text);
  if (text.empty()) return 0.0;
  if (text.size() > 40) throwParseError(where, field, "number too long: '" + std::string(text) + "'");
  // The usual D19.12 / E19.12 layout, with an exponent letter: the value parseDouble gives.
  if (double v; parseShortDecimal(text, v)) return v;
  char buf[48];
  std::size_t n = 0;
  bool exponent = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    char c = text[i];
    if (c == 'D' || c == 'd' || c == 'E' || c == 'e') {
      c = 'E';
      exponent = true;
    } else if ((c == '+' || c == '-') && i > 0 && !exponent &&
               (std::isdigit(static_cast<unsigned char>(text[i - 1])) || text[i - 1] == '.')) {
      buf[n++] = 'E';
      exponent = true;
    }
    buf[n++] = c;
  }
  return parseDouble(std::string_view(buf, n), where, field);
}

int toInt(double v, const TextLocation& where, std::string_view field) {
  if (!(std::fabs(v) < 2.0e9)) throwParseError(where, field, "value out of range");
  return static_cast<int>(std::lround(v));
}

// ---- record lines ------------------------------------------------------------------------------

struct RecordLines {
  std::vector<std::string> text;
  std::vector<std::int64_t> number;
  // Strings of earlier records, kept for their storage: one record after the other reuses them
  // instead of allocating every line anew.
  std::vector<std::string> spare;

  void reset() {
    for (auto& t : text) spare.push_back(std::move(t));
    text.clear();
    number.clear();
  }
  void add(const std::string& line, std::int64_t lineNumber) {
    if (spare.empty()) {
      text.push_back(line);
    } else {
      text.push_back(std::move(spare.back()));
      spare.pop_back();
      text.back().assign(line);
    }
    number.push_back(lineNumber);
  }
};

class NavReader {
 public:
  explicit NavReader(LineReader& in) : in_(in) {}
  NavData run();

 private:
  LineReader& in_;
  NavData nav_;
  double version_ = 0.0;
  char fileType_ = 'N';
  std::optional<System> fileSystem_;  // v2: system of every record
  bool rinex2_ = false;
  bool rinex4_ = false;
  std::string line_;
  std::string continuation_;  // readContinuation's line
  RecordLines record_;        // the record being read (storage reused)
  // RINEX 4 ION records: keep the newest per source.
  std::array<GpsTime, 4> ionEpoch_{};

  TextLocation here() const { return in_.location(); }
  TextLocation at(const RecordLines& r, std::size_t i) const { return {in_.name(), r.number[i]}; }

  void readHeader();
  void parseHeaderLine(const std::string& line, std::string_view label);
  void readBody();
  void readRinex4Body();

  // Data field k (0-3) of record line i: the first line holds three values after the epoch.
  double field(const RecordLines& r, std::size_t i, int k, std::string_view name) const;
  int indent() const { return rinex2_ ? 3 : 4; }
  bool isContinuation(const std::string& line) const;
  bool isBlank(const std::string& line) const { return trim(line).empty(); }
  // Reads up to maxLines continuation lines after the first line (already in r); fewer than
  // minLines is a truncated record.
  void readContinuation(RecordLines& r, int minLines, int maxLines, std::string_view what, bool untilMarker);

  CalendarTime parseEpoch(std::string_view text, const TextLocation& where) const;
  std::optional<SatId> recordSatellite(const std::string& line, const TextLocation& where) const;

  void parseKepler(const RecordLines& r, SatId sat, std::optional<NavMessage> message);
  void parseGlonass(const RecordLines& r, SatId sat);
  GpsTime glonassUtcToGpst(const CalendarTime& utc) const;
  void skipRecord(const std::string& reason) { nav_.skipped.push_back(reason); }
};

bool NavReader::isContinuation(const std::string& line) const {
  if (rinex4_ && !line.empty() && line[0] == '>') return false;
  const std::size_t ind = static_cast<std::size_t>(indent());
  if (line.size() <= ind) return false;
  for (std::size_t i = 0; i < ind; ++i) {
    if (line[i] != ' ') return false;
  }
  return !isBlank(line);
}

double NavReader::field(const RecordLines& r, std::size_t i, int k, std::string_view name) const {
  std::size_t pos;
  if (i == 0) {
    // First line: RINEX 3/4 "G05 yyyy mm dd hh mm ss" ends at column 23; RINEX 2 " 5 yy mm dd hh
    // mm ss.s" at column 22 (a letter-first RINEX 2 record uses the RINEX 3 layout).
    const bool v2Layout = rinex2_ && !r.text[0].empty() && !std::isalpha(static_cast<unsigned char>(r.text[0][0]));
    pos = (v2Layout ? 22 : 23) + 19 * static_cast<std::size_t>(k - 1);
  } else {
    pos = static_cast<std::size_t>(indent()) + 19 * static_cast<std::size_t>(k);
  }
  return navNumber(column(r.text[i], pos, 19), at(r, i), name);
}

CalendarTime NavReader::parseEpoch(std::string_view text, const TextLocation& where) const {
  // Whitespace-separated year month day hour minute second (RINEX 2 two-digit years map to
  // 1980-2079, RINEX 2.11 section 6.5).
  std::array<std::string_view, 6> tok{};
  std::size_t n = 0, i = 0;
  while (i < text.size() && n < 6) {
    while (i < text.size() && text[i] == ' ') ++i;
    if (i >= text.size()) break;
    const std::size_t start = i;
    while (i < text.size() && text[i] != ' ') ++i;
    tok[n++] = text.substr(start, i - start);
  }
  if (n < 6) throwParseError(where, "epoch", "incomplete epoch '" + std::string(trim(text)) + "'");
  CalendarTime c;
  c.year = static_cast<int>(parseInt(tok[0], where, "epoch year"));
  if (tok[0].size() <= 2) c.year += c.year < 80 ? 2000 : 1900;
  c.month = static_cast<int>(parseInt(tok[1], where, "epoch month"));
  c.day = static_cast<int>(parseInt(tok[2], where, "epoch day"));
  c.hour = static_cast<int>(parseInt(tok[3], where, "epoch hour"));
  c.minute = static_cast<int>(parseInt(tok[4], where, "epoch minute"));
  c.second = parseDouble(tok[5], where, "epoch second");
  if (c.year < 1980 || c.year > 2200 || !isValidCalendar(c)) {
    throwParseError(where, "epoch", "invalid date/time '" + std::string(trim(text)) + "'");
  }
  return c;
}

std::optional<SatId> NavReader::recordSatellite(const std::string& line, const TextLocation& where) const {
  if (trim(line).empty()) throwParseError(where, "satellite", "missing satellite and epoch line");
  if (rinex2_ && !std::isalpha(static_cast<unsigned char>(line[0]))) {
    const long prn = parseInt(column(line, 0, 2), where, "satellite number");
    SatId s(*fileSystem_, static_cast<int>(prn));
    if (*fileSystem_ == System::Sbas && prn >= 100) s = SatId(System::Sbas, static_cast<int>(prn - 100));
    if (*fileSystem_ == System::Qzss && prn >= 193) s = SatId(System::Qzss, static_cast<int>(prn - 192));
    if (prn < 0 || prn > 255 || !s.valid()) return std::nullopt;
    return s;
  }
  const std::string_view id = column(line, 0, 3);
  if (!systemFromLetter(id[0])) {
    throwParseError(where, "satellite system", "unknown satellite system in '" + std::string(id) + "'");
  }
  const long prn = parseInt(id.substr(1), where, "satellite number");
  const System sys = *systemFromLetter(id[0]);
  if (prn < 0 || prn > 255) return std::nullopt;
  const SatId s(sys, static_cast<int>(prn));
  if (!s.valid()) return std::nullopt;
  return s;
}

void NavReader::readContinuation(RecordLines& r, int minLines, int maxLines, std::string_view what,
                                 bool untilMarker) {
  std::string& line = continuation_;
  int got = 0;
  while (untilMarker || got < maxLines) {
    if (!in_.next(line)) break;
    if (!isContinuation(line)) {
      in_.unread();
      break;
    }
    r.add(line, in_.lineNumber());
    ++got;
  }
  if (got < minLines) {
    const std::int64_t lineNo = r.number.back() + 1;
    throwParseError({in_.name(), lineNo}, "BROADCAST ORBIT - " + std::to_string(got + 1),
                    std::string(what) + " record truncated: " + std::to_string(got) + " of " +
                        std::to_string(minLines) + " orbit lines");
  }
}

GpsTime NavReader::glonassUtcToGpst(const CalendarTime& utc) const {
  GpsTime t = utcToGpst(utc);
  // A header announcing more leap seconds than the built-in table (a table older than the file)
  // is trusted for one or two extra seconds.
  if (nav_.leapSeconds) {
    const int extra = *nav_.leapSeconds - leapSecondsAtUtc(utc);
    if (extra >= 1 && extra <= 2) t += static_cast<double>(extra);
  }
  return t;
}

// ---- header ------------------------------------------------------------------------------------

void NavReader::readHeader() {
  if (!in_.next(line_)) throw ParseError(in_.name(), 0, "RINEX VERSION / TYPE", "empty file");
  if (trim(column(line_, 60, 20)) != "RINEX VERSION / TYPE") {
    throwParseError(here(), "RINEX VERSION / TYPE", "first line is not a RINEX VERSION / TYPE line");
  }
  version_ = parseDouble(column(line_, 0, 9), here(), "RINEX version");
  if (!(version_ >= 2.0 && version_ < 5.0)) {
    throwParseError(here(), "RINEX version", "unsupported RINEX version " + std::string(trim(column(line_, 0, 9))));
  }
  nav_.version = version_;
  rinex2_ = version_ < 3.0;
  rinex4_ = version_ >= 4.0;
  const std::string_view typeCol = column(line_, 20, 1);
  fileType_ = typeCol.empty() ? ' ' : typeCol[0];
  const std::string_view sysCol = column(line_, 40, 1);
  const char sysChar = sysCol.empty() ? ' ' : sysCol[0];
  if (rinex2_) {
    switch (fileType_) {
      case 'N': fileSystem_ = systemFromLetter(sysChar).value_or(System::Gps); break;
      case 'G': fileSystem_ = System::Glonass; break;
      case 'H': fileSystem_ = System::Sbas; break;
      case 'E':
      case 'L': fileSystem_ = System::Galileo; break;
      case 'J':
      case 'Q': fileSystem_ = System::Qzss; break;
      default:
        throwParseError(here(), "RINEX VERSION / TYPE",
                        std::string("not a navigation file (type '") + fileType_ + "')");
    }
  } else if (fileType_ != 'N' && fileType_ != 'G' && fileType_ != 'H') {
    // RINEX 3.00/3.01 single-system files used G (GLONASS) and H (SBAS) like RINEX 2.
    throwParseError(here(), "RINEX VERSION / TYPE", std::string("not a navigation file (type '") + fileType_ + "')");
  }

  while (true) {
    if (!in_.next(line_)) throwParseError(here(), "END OF HEADER", "file ends inside the header");
    const std::string_view label = trim(column(line_, 60, 20));
    if (label == "END OF HEADER") break;
    parseHeaderLine(line_, label);
  }
}

void NavReader::parseHeaderLine(const std::string& line, std::string_view label) {
  const TextLocation w = here();
  auto klobuchar = [](std::optional<KlobucharParameters>& k) -> KlobucharParameters& {
    if (!k) k = KlobucharParameters{};
    return *k;
  };
  if (label == "ION ALPHA" || label == "ION BETA") {  // RINEX 2: 2X,4D12.4
    auto& k = klobuchar(nav_.iono.gps);
    auto& dst = label == "ION ALPHA" ? k.alpha : k.beta;
    for (int i = 0; i < 4; ++i) dst[i] = navNumber(column(line, 2 + 12 * i, 12), w, std::string(label));
  } else if (label == "IONOSPHERIC CORR") {  // RINEX 3: A4,1X,4D12.4
    const std::string_view type = column(line, 0, 4);
    std::array<double, 4> v{};
    for (int i = 0; i < 4; ++i) v[i] = navNumber(column(line, 5 + 12 * i, 12), w, "IONOSPHERIC CORR");
    auto setAlpha = [&](std::optional<KlobucharParameters>& k, bool alpha) {
      const bool fresh = !k;
      auto& kk = klobuchar(k);
      auto& dst = alpha ? kk.alpha : kk.beta;
      // Several BDSA/BDSB lines (one per broadcasting satellite, RINEX 3.04) keep the first.
      if (fresh || std::all_of(dst.begin(), dst.end(), [](double x) { return x == 0.0; })) dst = v;
    };
    if (type == "GPSA") setAlpha(nav_.iono.gps, true);
    else if (type == "GPSB") setAlpha(nav_.iono.gps, false);
    else if (type == "QZSA") setAlpha(nav_.iono.qzss, true);
    else if (type == "QZSB") setAlpha(nav_.iono.qzss, false);
    else if (type == "BDSA") setAlpha(nav_.iono.beidou, true);
    else if (type == "BDSB") setAlpha(nav_.iono.beidou, false);
    else if (trim(type) == "GAL") {
      if (!nav_.iono.galileo) nav_.iono.galileo = NeQuickParameters{{v[0], v[1], v[2]}};
    } else if (type == "IRNA" || type == "IRNB") {
      // NavIC Klobuchar: not used by this library.
    } else {
      throwParseError(w, "IONOSPHERIC CORR", "unknown correction type '" + std::string(type) + "'");
    }
  } else if (label == "DELTA-UTC: A0,A1,T,W") {  // RINEX 2: 3X,2D19.12,2I9
    TimeSystemCorrection c;
    std::memcpy(c.type, "GPUT", 4);
    c.a0 = navNumber(column(line, 3, 19), w, "DELTA-UTC A0");
    c.a1 = navNumber(column(line, 22, 19), w, "DELTA-UTC A1");
    c.referenceTow = static_cast<double>(parseOptionalInt(column(line, 41, 9), w, "DELTA-UTC T").value_or(0));
    c.referenceWeek = static_cast<int>(parseOptionalInt(column(line, 50, 9), w, "DELTA-UTC W").value_or(0));
    nav_.timeCorrections.push_back(c);
  } else if (label == "CORR TO SYSTEM TIME") {  // RINEX 2 GLONASS: 3I6,3X,D19.12 (-tauC)
    TimeSystemCorrection c;
    std::memcpy(c.type, "GLUT", 4);
    CalendarTime d;
    d.year = static_cast<int>(parseOptionalInt(column(line, 0, 6), w, "CORR TO SYSTEM TIME year").value_or(0));
    d.month = static_cast<int>(parseOptionalInt(column(line, 6, 6), w, "CORR TO SYSTEM TIME month").value_or(1));
    d.day = static_cast<int>(parseOptionalInt(column(line, 12, 6), w, "CORR TO SYSTEM TIME day").value_or(1));
    if (d.year >= 1980 && d.year < 2200 && isValidCalendar(d)) {
      const GpsTime ref = GpsTime::fromCalendar(d);
      c.referenceWeek = ref.week();
      c.referenceTow = ref.tow();
    }
    c.a0 = navNumber(column(line, 21, 19), w, "CORR TO SYSTEM TIME");
    nav_.timeCorrections.push_back(c);
  } else if (label == "TIME SYSTEM CORR") {  // RINEX 3: A4,1X,D17.10,D16.9,1X,I6,1X,I4
    TimeSystemCorrection c;
    const std::string_view type = column(line, 0, 4);
    if (trim(type).size() != 4) throwParseError(w, "TIME SYSTEM CORR", "missing correction type");
    std::memcpy(c.type, type.data(), 4);
    c.a0 = navNumber(column(line, 5, 17), w, "TIME SYSTEM CORR A0");
    c.a1 = navNumber(column(line, 22, 16), w, "TIME SYSTEM CORR A1");
    c.referenceTow = static_cast<double>(parseOptionalInt(column(line, 38, 7), w, "TIME SYSTEM CORR T").value_or(0));
    c.referenceWeek = static_cast<int>(parseOptionalInt(column(line, 45, 5), w, "TIME SYSTEM CORR W").value_or(0));
    nav_.timeCorrections.push_back(c);
  } else if (label == "LEAP SECONDS") {  // I6 (RINEX 3: 4I6,A3 with the time system, BDS or GPS)
    const auto leap = parseOptionalInt(column(line, 0, 6), w, "LEAP SECONDS");
    if (leap) {
      if (*leap < 0 || *leap > 100) throwParseError(w, "LEAP SECONDS", "implausible leap second count");
      int v = static_cast<int>(*leap);
      if (!rinex2_ && trim(column(line, 24, 3)) == "BDS") v += 14;  // BDT - UTC to GPST - UTC
      nav_.leapSeconds = v;
    }
  }
  // All other header lines (PGM / RUN BY / DATE, COMMENT, MERGED FILE, DOI, ...) carry nothing
  // this reader needs.
}

// ---- records -----------------------------------------------------------------------------------

void NavReader::parseKepler(const RecordLines& r, SatId sat, std::optional<NavMessage> message) {
  KeplerEphemeris e;
  e.sat = sat;
  const System sys = sat.system;
  const std::size_t epochStart = (rinex2_ && !std::isalpha(static_cast<unsigned char>(r.text[0][0]))) ? 2 : 3;
  const CalendarTime epoch = parseEpoch(column(r.text[0], epochStart, 20), at(r, 0));

  e.af0 = field(r, 0, 1, "SV clock bias");
  e.af1 = field(r, 0, 2, "SV clock drift");
  e.af2 = field(r, 0, 3, "SV clock drift rate");
  const double iod = field(r, 1, 0, sys == System::Galileo ? "IODnav" : sys == System::BeiDou ? "AODE" : "IODE");
  e.crs = field(r, 1, 1, "Crs");
  e.deltaN = field(r, 1, 2, "Delta n");
  e.m0 = field(r, 1, 3, "M0");
  e.cuc = field(r, 2, 0, "Cuc");
  e.e = field(r, 2, 1, "e");
  e.cus = field(r, 2, 2, "Cus");
  e.sqrtA = field(r, 2, 3, "sqrt(A)");
  const double toes = field(r, 3, 0, "Toe");
  e.cic = field(r, 3, 1, "Cic");
  e.omega0 = field(r, 3, 2, "OMEGA0");
  e.cis = field(r, 3, 3, "Cis");
  e.i0 = field(r, 4, 0, "i0");
  e.crc = field(r, 4, 1, "Crc");
  e.omega = field(r, 4, 2, "omega");
  e.omegaDot = field(r, 4, 3, "OMEGA DOT");
  e.iDot = field(r, 5, 0, "IDOT");
  const double codes = field(r, 5, 1, sys == System::Galileo ? "data sources" : "codes on L2");
  (void)field(r, 5, 2, "week");  // validated; the week is taken from the epoch (see below)
  const double l2p = field(r, 5, 3, "L2 P data flag");
  e.ura = field(r, 6, 0, "SV accuracy");
  e.health = toInt(field(r, 6, 1, "SV health"), at(r, 6), "SV health");
  const double tgd0 = field(r, 6, 2, "TGD");
  const double tgd1 = field(r, 6, 3, sys == System::BeiDou ? "TGD2" : sys == System::Galileo ? "BGD E5b/E1" : "IODC");
  const bool hasLast = r.text.size() > 7;
  const double ttrTow = hasLast ? field(r, 7, 0, "transmission time") : 1.0e10;
  const double last2 = hasLast ? field(r, 7, 1, sys == System::BeiDou ? "AODC" : "fit interval") : 0.0;

  if (!(toes > -kWeek && toes < 2.0 * kWeek)) throwParseError(at(r, 3), "Toe", "time of ephemeris out of range");
  e.iode = toInt(iod, at(r, 1), "IODE");
  e.codesOnL2 = toInt(codes, at(r, 5), "codes on L2");
  e.l2pDataFlag = toInt(l2p, at(r, 5), "L2 P data flag");

  // Times. The clock epoch is in the system's own time scale; toe and ttr are seconds of its
  // week and are placed in the week that puts them nearest to toc (robust against 10-bit or
  // otherwise wrong week fields in old files, and against toe/toc on different sides of a week
  // boundary).
  const double scaleToGpst = sys == System::BeiDou ? -kBdtMinusGpst : 0.0;  // BDT + 14 s = GPST
  const GpsTime tocOwn = GpsTime::fromCalendar(epoch);
  const GpsTime toeOwn = nearestTow(toes, tocOwn);
  e.toc = tocOwn + scaleToGpst;
  e.toe = toeOwn + scaleToGpst;
  e.toeSeconds = (toes >= 0.0 && toes < kWeek) ? toes : toeOwn.tow();
  if (std::fabs(ttrTow) < 2.0 * kWeek) e.ttr = nearestTow(ttrTow, toeOwn) + scaleToGpst;
  switch (sys) {
    case System::Galileo: e.week = toeOwn.week() - kGstWeekOffset; break;
    case System::BeiDou: e.week = toeOwn.week() - kBdtWeekOffset; break;
    default: e.week = toeOwn.week(); break;
  }

  switch (sys) {
    case System::Gps:
    case System::Qzss:
      e.message = sys == System::Gps ? NavMessage::GpsLnav : NavMessage::QzssLnav;
      e.iodc = toInt(tgd1, at(r, 6), "IODC");
      e.tgd = {tgd0, 0.0};
      if (sys == System::Qzss) {
        // RINEX 3 gives the QZSS fit interval flag (IS-QZSS 4.1.2.7: 0 = 2 h, 1 = more than 2 h,
        // taken as 4 h); some writers give hours instead.
        e.fitInterval = last2 > 1.5 ? last2 : (last2 > 0.5 ? 4.0 : 2.0);
      } else {
        e.fitInterval = last2;
      }
      break;
    case System::Galileo:
      e.message = message.value_or(galileoMessageFromDataSources(e.codesOnL2));
      e.iodc = e.iode;
      e.tgd = {tgd0, tgd1};
      break;
    case System::BeiDou:
      e.message = message.value_or(isBeiDouGeo(sat) ? NavMessage::BeiDouD2 : NavMessage::BeiDouD1);
      e.iodc = toInt(last2, at(r, hasLast ? 7 : 6), "AODC");
      e.tgd = {tgd0, tgd1};
      break;
    default:
      break;
  }
  nav_.kepler.push_back(e);
}

void NavReader::parseGlonass(const RecordLines& r, SatId sat) {
  GlonassEphemeris g;
  g.sat = sat;
  const bool v2Layout = rinex2_ && !std::isalpha(static_cast<unsigned char>(r.text[0][0]));
  const CalendarTime epoch = parseEpoch(column(r.text[0], v2Layout ? 2 : 3, 20), at(r, 0));
  const double minusTauN = field(r, 0, 1, "-TauN");
  g.gammaN = field(r, 0, 2, "GammaN");
  const double tk = field(r, 0, 3, "message frame time");
  g.tauN = -minusTauN;
  const char* axes[3] = {"X", "Y", "Z"};
  for (int i = 0; i < 3; ++i) {
    const std::string ax = axes[i];
    g.position[i] = field(r, 1 + i, 0, ax) * 1e3;  // km -> m
    g.velocity[i] = field(r, 1 + i, 1, ax + " velocity") * 1e3;
    g.acceleration[i] = field(r, 1 + i, 2, ax + " acceleration") * 1e3;
  }
  g.health = toInt(field(r, 1, 3, "health"), at(r, 1), "health");
  const double k = field(r, 2, 3, "frequency number");
  g.frequencyChannel = toInt(k, at(r, 2), "frequency number");
  if (g.frequencyChannel < -7 || g.frequencyChannel > 13) {
    throwParseError(at(r, 2), "frequency number", "frequency channel out of range");
  }
  g.age = toInt(field(r, 3, 3, "age of operation"), at(r, 3), "age of operation");
  if (r.text.size() > 4) {  // RINEX 3.05 / 4: status flags, L1/L2 delay difference, URAI, health flags
    g.deltaTauN = field(r, 4, 1, "L1/L2 group delay difference");
    const double urai = field(r, 4, 2, "URAI");
    // Accuracy index F_T to metres (GLONASS ICD 5.1 table 4.4); 15 = not given.
    static constexpr double kFt[15] = {1, 2, 2.5, 4, 5, 7, 10, 12, 14, 16, 32, 64, 128, 256, 512};
    const int ft = toInt(urai, at(r, 4), "URAI");
    if (ft >= 0 && ft < 15) g.accuracy = kFt[ft];
  }
  g.toe = glonassUtcToGpst(epoch);
  // tb index: Moscow time (UTC + 3 h) of day in 15-minute units.
  const double sodUtc = epoch.hour * 3600.0 + epoch.minute * 60.0 + epoch.second;
  g.iode = static_cast<int>(std::lround(std::fmod(sodUtc + 10800.0, kDay) / 900.0)) % 96;
  // Message frame time: seconds of the UTC week (RINEX 3/4) or of the UTC day (RINEX 2), put into
  // the week/day nearest to tb.
  if (std::fabs(tk) < 2.0 * kWeek) {
    CalendarTime dayStart = epoch;
    dayStart.hour = dayStart.minute = 0;
    dayStart.second = 0.0;
    const GpsTime utcDay = GpsTime::fromCalendar(dayStart);  // UTC instant counted like GPST
    const GpsTime utcToe = GpsTime::fromCalendar(epoch);
    GpsTime tofUtc;
    if (rinex2_ && tk < kDay) {
      tofUtc = utcDay + tk;
      const double d = tofUtc - utcToe;
      if (d > kDay / 2) tofUtc -= kDay;
      else if (d < -kDay / 2) tofUtc += kDay;
    } else {
      tofUtc = nearestTow(tk, utcToe);
    }
    g.tof = tofUtc + (g.toe - utcToe);  // same leap-second offset as tb
  }
  nav_.glonass.push_back(g);
}

void NavReader::readBody() {
  if (rinex4_) {
    readRinex4Body();
    return;
  }
  std::string line;
  while (in_.next(line)) {
    if (isBlank(line)) continue;
    const TextLocation w = here();
    if (isContinuation(line)) throwParseError(w, "SV / EPOCH / SV CLK", "orbit line without a record start");
    RecordLines& r = record_;
    r.reset();
    r.add(line, in_.lineNumber());
    const auto sat = recordSatellite(line, w);
    // System of the record: from the satellite, or from the letter when the number is unknown.
    System sys;
    if (rinex2_ && !std::isalpha(static_cast<unsigned char>(line[0]))) sys = *fileSystem_;
    else sys = *systemFromLetter(line[0]);
    const int lines = (sys == System::Glonass || sys == System::Sbas) ? 3 : 7;
    const int maxLines = sys == System::Glonass && !rinex2_ ? 4 : lines;
    const int minLines = (sys == System::Glonass || sys == System::Sbas) ? 3 : 6;
    readContinuation(r, minLines, maxLines, systemName(sys), false);
    const std::string where = "line " + std::to_string(r.number[0]) + ": ";
    if (!sat) {
      skipRecord(where + "record of an unknown satellite '" + std::string(trim(column(line, 0, 3))) + "' skipped");
      continue;
    }
    switch (sys) {
      case System::Gps:
      case System::Galileo:
      case System::BeiDou:
      case System::Qzss:
        parseKepler(r, *sat, std::nullopt);
        break;
      case System::Glonass:
        parseGlonass(r, *sat);
        break;
      case System::Sbas:
        skipRecord(where + sat->str() + " SBAS ephemeris skipped (not used by this library)");
        break;
      case System::Navic:
        skipRecord(where + sat->str() + " NavIC ephemeris skipped (not used by this library)");
        break;
    }
  }
}

void NavReader::readRinex4Body() {
  std::string line;
  while (in_.next(line)) {
    if (isBlank(line)) continue;
    const TextLocation w = here();
    if (line[0] != '>') throwParseError(w, "record type", "expected a '>' record line");
    // "> EPH G05 LNAV": record type, satellite (or system letter), message type.
    std::array<std::string_view, 3> tok{};
    std::size_t n = 0, i = 1;
    const std::string_view sv(line);
    while (i < sv.size() && n < 3) {
      while (i < sv.size() && sv[i] == ' ') ++i;
      if (i >= sv.size()) break;
      const std::size_t start = i;
      while (i < sv.size() && sv[i] != ' ') ++i;
      tok[n++] = sv.substr(start, i - start);
    }
    // The satellite field may be a bare system letter ("> STO E   IFNV").
    if (n < 3) throwParseError(w, "record type", "incomplete record line '" + line + "'");
    const std::string type(tok[0]), msg(tok[2]);
    const std::string satText(tok[1]);  // copied: `line` is reused below
    const std::string where = "line " + std::to_string(w.line) + ": ";
    if (!systemFromLetter(satText[0])) {
      throwParseError(w, "satellite system", "unknown satellite system in '" + line + "'");
    }
    const System sys = *systemFromLetter(satText[0]);
    RecordLines& r = record_;
    r.reset();
    if (!in_.next(line) || (!line.empty() && line[0] == '>')) {
      throwParseError({in_.name(), w.line + 1}, type == "EPH" ? "SV / EPOCH / SV CLK" : "epoch",
                      type + " record without data lines");
    }
    r.add(line, in_.lineNumber());

    if (type == "EPH") {
      std::optional<NavMessage> message;
      bool glonass = false;
      if ((sys == System::Gps || sys == System::Qzss) && msg == "LNAV") {
        message = sys == System::Gps ? NavMessage::GpsLnav : NavMessage::QzssLnav;
      } else if (sys == System::Galileo && msg == "INAV") {
        message = NavMessage::GalileoInav;
      } else if (sys == System::Galileo && msg == "FNAV") {
        message = NavMessage::GalileoFnav;
      } else if (sys == System::BeiDou && msg == "D1") {
        message = NavMessage::BeiDouD1;
      } else if (sys == System::BeiDou && msg == "D2") {
        message = NavMessage::BeiDouD2;
      } else if (sys == System::Glonass && msg == "FDMA") {
        glonass = true;
      }
      if (!message && !glonass) {
        readContinuation(r, 0, 0, "EPH", true);
        skipRecord(where + "EPH " + std::string(trim(satText)) + " " + msg + " skipped (message type not decoded)");
        continue;
      }
      const auto sat = recordSatellite(r.text[0], at(r, 0));
      if (!sat) {
        readContinuation(r, 0, 0, "EPH", true);
        skipRecord(where + "EPH of an unknown satellite '" + std::string(column(r.text[0], 0, 3)) + "' skipped");
        continue;
      }
      if (sat->system != sys) {
        throwParseError(at(r, 0), "satellite", "record satellite differs from the '>' line");
      }
      readContinuation(r, glonass ? 3 : 6, glonass ? 4 : 7, glonass ? "GLONASS" : systemName(sys), false);
      if (glonass) parseGlonass(r, *sat);
      else parseKepler(r, *sat, message);
      continue;
    }

    // STO / ION / EOP: an epoch line "    yyyy mm dd hh mm ss" followed by data fields.
    readContinuation(r, 0, 0, type, true);
    const CalendarTime epoch = parseEpoch(column(r.text[0], 4, 19), at(r, 0));
    auto need = [&](std::size_t lines, const char* field) {
      if (r.text.size() < lines) {
        throwParseError({in_.name(), r.number.back() + 1}, field, type + " record truncated");
      }
    };
    if (type == "STO") {
      need(2, "STO transmission time");
      TimeSystemCorrection c;
      const std::string_view code = column(r.text[0], 24, 4);
      if (trim(code).size() != 4) throwParseError(at(r, 0), "STO time offset type", "missing offset type");
      std::memcpy(c.type, code.data(), 4);
      GpsTime ref = GpsTime::fromCalendar(epoch);
      c.referenceWeek = ref.week() - (sys == System::BeiDou ? kBdtWeekOffset : 0);
      c.referenceTow = ref.tow();
      (void)field(r, 1, 0, "STO transmission time");
      c.a0 = field(r, 1, 1, "STO A0");
      c.a1 = field(r, 1, 2, "STO A1");
      c.a2 = field(r, 1, 3, "STO A2");
      nav_.timeCorrections.push_back(c);
    } else if (type == "ION") {
      const GpsTime when = GpsTime::fromCalendar(epoch);
      auto newer = [&](int slot) {
        if (ionEpoch_[slot] == GpsTime{} || ionEpoch_[slot] < when) {
          ionEpoch_[slot] = when;
          return true;
        }
        return false;
      };
      const bool klob = ((sys == System::Gps || sys == System::Qzss) && (msg == "LNAV" || msg == "CNVX")) ||
                        (sys == System::BeiDou && msg == "D1D2");
      if (klob) {
        need(3, "ION beta");
        KlobucharParameters k;
        k.alpha = {field(r, 0, 1, "ION alpha0"), field(r, 0, 2, "ION alpha1"), field(r, 0, 3, "ION alpha2"),
                   field(r, 1, 0, "ION alpha3")};
        k.beta = {field(r, 1, 1, "ION beta0"), field(r, 1, 2, "ION beta1"), field(r, 1, 3, "ION beta2"),
                  field(r, 2, 0, "ION beta3")};
        const int slot = sys == System::Gps ? 0 : sys == System::Qzss ? 1 : 2;
        auto& dst = sys == System::Gps ? nav_.iono.gps : sys == System::Qzss ? nav_.iono.qzss : nav_.iono.beidou;
        if (newer(slot)) dst = k;
      } else if (sys == System::Galileo && msg == "IFNV") {
        NeQuickParameters q;
        q.ai = {field(r, 0, 1, "ION ai0"), field(r, 0, 2, "ION ai1"), field(r, 0, 3, "ION ai2")};
        if (newer(3)) nav_.iono.galileo = q;
      } else {
        skipRecord(where + "ION " + std::string(trim(satText)) + " " + msg + " skipped (model not used)");
      }
    } else if (type == "EOP") {
      need(3, "EOP");
      for (std::size_t li = 0; li < r.text.size(); ++li) {
        for (int k = (li == 0 ? 1 : 0); k < 4; ++k) (void)field(r, li, k, "EOP");
      }
      skipRecord(where + "EOP " + std::string(trim(satText)) + " " + msg +
                 " skipped (Earth orientation parameters are not used)");
    } else {
      skipRecord(where + "unknown record type '" + type + "' skipped");
    }
  }
}

NavData NavReader::run() {
  readHeader();
  readBody();
  return std::move(nav_);
}

}  // namespace

NavData readRinexNav(const std::string& path) {
  LineReader in(path);
  NavReader r(in);
  return r.run();
}

NavData parseRinexNav(std::string_view text, std::string_view name) {
  LineReader in(text, std::string(name));
  NavReader r(in);
  return r.run();
}

void mergeNavData(NavData& a, const NavData& b) {
  a.kepler.insert(a.kepler.end(), b.kepler.begin(), b.kepler.end());
  a.glonass.insert(a.glonass.end(), b.glonass.begin(), b.glonass.end());
  if (!a.iono.gps) a.iono.gps = b.iono.gps;
  if (!a.iono.qzss) a.iono.qzss = b.iono.qzss;
  if (!a.iono.beidou) a.iono.beidou = b.iono.beidou;
  if (!a.iono.galileo) a.iono.galileo = b.iono.galileo;
  for (const auto& c : b.timeCorrections) {
    const bool have = std::any_of(a.timeCorrections.begin(), a.timeCorrections.end(),
                                  [&](const TimeSystemCorrection& x) { return std::memcmp(x.type, c.type, 4) == 0; });
    if (!have) a.timeCorrections.push_back(c);
  }
  if (!a.leapSeconds) a.leapSeconds = b.leapSeconds;
  a.skipped.insert(a.skipped.end(), b.skipped.begin(), b.skipped.end());
}

}  // namespace gvins
