// RINEX observation reader. Formats follow RINEX 2.11 (Gurtner & Estey, 2007) and RINEX 3.05
// (IGS/RTCM-SC104, 2020): header labels in columns 61-80, epoch records and observation records
// with F14.3 values followed by the loss-of-lock indicator and the signal strength digit.
#include "gvins/base/rinex_obs_reader.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "gvins/base/text_fields.hpp"

namespace gvins {

namespace {

constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,
                             1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18};

bool isDigit(char c) { return c >= '0' && c <= '9'; }

/// The layout RINEX writers use for F14.3: blanks, an optional sign and digits in columns 1-10,
/// the point in column 11, three decimals. Same mantissa and scale as the general loop below
/// (at most 13 digits), hence the same value.
bool fixedF14_3(std::string_view s, double& out) {
  if (s.size() != 14 || s[10] != '.' || !isDigit(s[11]) || !isDigit(s[12]) || !isDigit(s[13])) return false;
  std::size_t i = 0;
  while (i < 10 && s[i] == ' ') ++i;
  bool neg = false;
  if (i < 10 && (s[i] == '-' || s[i] == '+')) {
    neg = s[i] == '-';
    ++i;
  }
  std::uint64_t m = 0;
  for (; i < 10; ++i) {
    if (!isDigit(s[i])) return false;
    m = m * 10 + static_cast<unsigned>(s[i] - '0');
  }
  m = m * 1000 + static_cast<unsigned>(s[11] - '0') * 100 + static_cast<unsigned>(s[12] - '0') * 10 +
      static_cast<unsigned>(s[13] - '0');
  const double v = static_cast<double>(m) / kPow10[3];
  out = neg ? -v : v;
  return true;
}

/// Plain fixed-point decimal ("  -1234.567") without exponent. The digits form an integer below
/// 2^53, so mantissa / 10^k is the correctly rounded value (same result as strtod). Returns false
/// for anything else, blank included; the caller then falls back to the general parser.
enum class Fast { Blank, Value, Other };

Fast fastDecimal(std::string_view s, double& out) {
  if (fixedF14_3(s, out)) return Fast::Value;
  std::size_t i = 0;
  const std::size_t n = s.size();
  while (i < n && s[i] == ' ') ++i;
  if (i == n) return Fast::Blank;
  bool neg = false;
  if (i < n && (s[i] == '-' || s[i] == '+')) {
    neg = s[i] == '-';
    ++i;
  }
  std::uint64_t m = 0;
  int digits = 0, frac = 0;
  bool dot = false;
  for (; i < n; ++i) {
    const char c = s[i];
    if (c >= '0' && c <= '9') {
      if (++digits > 17) return Fast::Other;
      m = m * 10 + static_cast<unsigned>(c - '0');
      if (dot) ++frac;
    } else if (c == '.' && !dot) {
      dot = true;
    } else if (c == ' ') {
      for (; i < n; ++i) {
        if (s[i] != ' ') return Fast::Other;
      }
      break;
    } else {
      return Fast::Other;
    }
  }
  if (digits == 0 || m > (std::uint64_t{1} << 53)) return Fast::Other;
  double v = static_cast<double>(m);
  if (frac) v /= kPow10[frac];
  out = neg ? -v : v;
  return Fast::Value;
}

bool isBlank(std::string_view s) {
  for (char c : s) {
    if (c != ' ' && c != '\r') return false;
  }
  return true;
}

std::string_view label(std::string_view line) { return trimmedColumn(line, 60, 20); }

struct Column {
  int signal = -1;  // index into SystemLayout::codes; -1: column not stored
  ObsType type = ObsType::Code;
  double scale = 1.0;  // divide the file value by this ("SYS / SCALE FACTOR")
};

struct SystemLayout {
  std::vector<Column> columns;
  std::vector<ObsCode> codes;
};

int typeSlot(ObsType t) {
  switch (t) {
    case ObsType::Code: return 0;
    case ObsType::Phase: return 1;
    case ObsType::Doppler: return 2;
    case ObsType::Snr: return 3;
  }
  return 0;
}

constexpr std::uint8_t kTypeBit[4] = {SignalObs::kCode, SignalObs::kPhase, SignalObs::kDoppler,
                                      SignalObs::kSnr};

}  // namespace

struct RinexObsReader::Impl {
  LineReader in;
  RinexObsReaderOptions opt;
  RinexObsHeader hdr;
  std::array<SystemLayout, kNumSystems> layout;
  // Raw RINEX 3 type names per system in file order (ignored ones included).
  std::array<std::vector<std::string>, kNumSystems> rawTypes;
  std::array<int, kNumSystems> declaredTypes{};
  // Scale factors per system: (type name, or "" for all types) -> factor.
  std::array<std::vector<std::pair<std::string, double>>, kNumSystems> scale;
  int declaredR2Types = -1;
  int declaredSlots = -1;
  int slotCount = 0;
  // Continuation state of multi-line header records.
  int lastTypesSystem = -1;
  int lastScaleSystem = -1;
  double lastScaleFactor = 1.0;
  PhaseShiftRecord* lastPhaseShift = nullptr;
  bool typesChanged = false;

  std::vector<std::string> events;
  RinexObsReaderStats stats;
  std::string_view line;  // the line last read (valid until the next read)
  std::vector<std::string> satLines;  // RINEX 2 satellite list
  GpsTime lastTime;
  bool haveTime = false;
  // The last observation epoch returned (epochs must increase) and the line of the epoch last read.
  GpsTime lastObsTime;
  bool haveObsTime = false;
  std::int64_t epochLine = 0;
  // Scratch per signal: SSI of each of the four types.
  std::vector<std::array<std::uint8_t, 4>> ssiScratch;

  Impl(LineReader r, RinexObsReaderOptions o) : in(std::move(r)), opt(o) {}

  bool rinex2() const { return hdr.version < 3.0; }
  TextLocation where() const { return in.location(); }
  [[noreturn]] void fail(std::string_view field, const std::string& what) const {
    throwParseError(where(), field, what);
  }
  void note(const std::string& msg) {
    if (stats.messages.size() < opt.maxMessages) {
      stats.messages.push_back(in.name() + ":" + std::to_string(in.lineNumber()) + ": " + msg);
    }
  }

  void readHeader();
  void headerLine(std::string_view l, std::string_view lab, bool inFile);
  // Multi-field header records (headerLine).
  void obsTypesLine(std::string_view l, const TextLocation& w, const std::string& labStr);
  void rinex2TypesLine(std::string_view l, const TextLocation& w, const std::string& labStr);
  void scaleFactorLine(std::string_view l, const TextLocation& w, const std::string& labStr);
  void phaseShiftLine(std::string_view l, const TextLocation& w, const std::string& labStr);
  void glonassSlotLine(std::string_view l, const TextLocation& w, const std::string& labStr);
  void glonassBiasLine(std::string_view l, const TextLocation& w, const std::string& labStr);
  void observationTimeLine(std::string_view l, std::string_view lab, const TextLocation& w, const std::string& labStr);
  void buildLayouts();
  GpsTime epochTime(const CalendarTime& c) const;
  bool readEpoch(ObsEpoch& e);
  // Steps of readEpoch.
  GpsTime epochLineTime(std::string_view l) const;
  void readSpecialRecords(long nsat);
  std::size_t readRinex2Satellites(ObsEpoch& e, long nsat);
  std::size_t readRinex3Satellites(ObsEpoch& e, long nsat);
  SatObs& beginSat(ObsEpoch& e, std::size_t& used, SatId id, const SystemLayout& lay);
  void skipSat(std::string_view id, const char* why);
  void readSatValues(std::string_view l, std::size_t start, std::size_t perLine, SatObs& so,
                     const SystemLayout& lay, std::size_t firstColumn, std::size_t count);
  void finishSat(SatObs& so, const SystemLayout& lay);
  void resync();
  bool looksLikeEpoch(std::string_view l) const;
};

// ---------------------------------------------------------------------------------------------
// Header

void RinexObsReader::Impl::readHeader() {
  if (!in.next(line)) throwParseError({in.name(), 0}, "RINEX VERSION / TYPE", "empty file");
  const std::string_view first = line;
  if (label(first) == "CRINEX VERS   / TYPE" || column(first, 0, 20).find("CRINEX") != std::string_view::npos ||
      label(first).substr(0, 6) == "CRINEX") {
    fail("RINEX VERSION / TYPE",
         "Hatanaka-compressed (CRINEX) file; decompress it with crx2rnx first");
  }
  if (label(first) != "RINEX VERSION / TYPE") {
    fail("RINEX VERSION / TYPE", "not a RINEX file (first line has no 'RINEX VERSION / TYPE' label)");
  }
  hdr.version = parseDouble(column(first, 0, 9), where(), "RINEX VERSION / TYPE");
  if (!(hdr.version >= 2.0 && hdr.version < 5.0)) {
    fail("RINEX VERSION / TYPE", "unsupported RINEX version " + std::string(trim(column(first, 0, 9))));
  }
  const std::string_view type = trimmedColumn(first, 20, 1);
  if (type != "O") {
    fail("RINEX VERSION / TYPE",
         "not an observation file (file type '" + std::string(type) + "', expected 'O')");
  }
  const std::string_view sys = column(first, 40, 1);
  hdr.fileSystem = sys.empty() || sys[0] == ' ' ? 'G' : sys[0];
  if (hdr.fileSystem != 'M' && !systemFromLetter(hdr.fileSystem)) {
    fail("RINEX VERSION / TYPE", "unknown satellite system '" + std::string(sys) + "'");
  }
  // RINEX 3.05 A2: default time systems of single-system files.
  switch (hdr.fileSystem) {
    case 'R': hdr.timeSystem = "GLO"; break;
    case 'E': hdr.timeSystem = "GAL"; break;
    case 'C': hdr.timeSystem = "BDT"; break;
    case 'J': hdr.timeSystem = "QZS"; break;
    case 'I': hdr.timeSystem = "IRN"; break;
    default: hdr.timeSystem = "GPS"; break;
  }
  bool end = false;
  while (in.next(line)) {
    const std::string_view lab = label(line);
    if (lab == "END OF HEADER") {
      end = true;
      break;
    }
    headerLine(line, lab, false);
  }
  if (!end) fail("END OF HEADER", "file ends inside the header (no END OF HEADER)");
  if (rinex2() && hdr.rinex2Types.empty()) fail("# / TYPES OF OBSERV", "no observation types in the header");
  if (!rinex2()) {
    bool any = false;
    for (const auto& r : rawTypes) any |= !r.empty();
    if (!any) fail("SYS / # / OBS TYPES", "no observation types in the header");
  }
  buildLayouts();
  bool usable = false;
  for (const auto& t : hdr.obsTypes) usable |= !t.empty();
  if (!usable) {
    fail(rinex2() ? "# / TYPES OF OBSERV" : "SYS / # / OBS TYPES",
         "none of the observation types is a code, phase, Doppler or SNR measurement");
  }
}

void RinexObsReader::Impl::headerLine(std::string_view l, std::string_view lab, bool inFile) {
  const TextLocation w = where();
  const std::string labStr(lab);
  auto str = [&](std::size_t pos, std::size_t len) { return std::string(trimmedColumn(l, pos, len)); };
  if (lab == "COMMENT") {
    hdr.comments.push_back(std::string(trim(column(l, 0, 60))));
  } else if (lab == "PGM / RUN BY / DATE") {
    hdr.program = str(0, 20);
    hdr.runBy = str(20, 20);
    hdr.date = str(40, 20);
  } else if (lab == "MARKER NAME") {
    hdr.station.markerName = str(0, 60);
  } else if (lab == "MARKER NUMBER") {
    hdr.station.markerNumber = str(0, 20);
  } else if (lab == "MARKER TYPE") {
    hdr.markerType = str(0, 20);
  } else if (lab == "OBSERVER / AGENCY") {
    hdr.observer = str(0, 20);
    hdr.agency = str(20, 40);
  } else if (lab == "REC # / TYPE / VERS") {
    hdr.station.receiverNumber = str(0, 20);
    hdr.station.receiverType = str(20, 20);
    hdr.station.receiverVersion = str(40, 20);
  } else if (lab == "ANT # / TYPE") {
    hdr.station.antennaNumber = str(0, 20);
    hdr.station.antennaType = str(20, 20);
  } else if (lab == "APPROX POSITION XYZ") {
    Eigen::Vector3d p;
    for (int i = 0; i < 3; ++i) p[i] = parseDoubleOr(column(l, 14 * i, 14), 0.0, w, labStr);
    if (p.cwiseAbs().maxCoeff() > 1e8) fail(labStr, "coordinate out of range (more than 100000 km)");
    if (p.norm() > 0.0) hdr.station.approxPosition = p;
    else hdr.station.approxPosition.reset();
  } else if (lab == "ANTENNA: DELTA H/E/N") {
    for (int i = 0; i < 3; ++i) {
      const double v = parseDoubleOr(column(l, 14 * i, 14), 0.0, w, labStr);
      if (std::abs(v) > 1e6) fail(labStr, "antenna offset out of range (more than 1000 km)");
      hdr.station.antennaDeltaHen[i] = v;
    }
  } else if (lab == "SYS / # / OBS TYPES") {
    obsTypesLine(l, w, labStr);
  } else if (lab == "# / TYPES OF OBSERV") {
    rinex2TypesLine(l, w, labStr);
  } else if (lab == "SYS / SCALE FACTOR") {
    scaleFactorLine(l, w, labStr);
  } else if (lab == "SYS / PHASE SHIFT") {
    phaseShiftLine(l, w, labStr);
  } else if (lab == "GLONASS SLOT / FRQ #") {
    glonassSlotLine(l, w, labStr);
  } else if (lab == "GLONASS COD/PHS/BIS") {
    glonassBiasLine(l, w, labStr);
  } else if (lab == "TIME OF FIRST OBS" || lab == "TIME OF LAST OBS") {
    observationTimeLine(l, lab, w, labStr);
  } else if (lab == "INTERVAL") {
    const auto v = parseOptionalDouble(column(l, 0, 10), w, labStr);
    if (v && *v > 0.0 && *v < 1e6) hdr.interval = v;
  } else if (lab == "LEAP SECONDS") {
    const auto v = parseOptionalInt(column(l, 0, 6), w, labStr);
    if (v && *v >= -100 && *v <= 1000) hdr.leapSeconds = static_cast<int>(*v);
  } else if (lab == "RCV CLOCK OFFS APPL") {
    const auto v = parseOptionalInt(column(l, 0, 6), w, labStr);
    hdr.receiverClockOffsetApplied = v && *v == 1;
  } else if (lab == "SIGNAL STRENGTH UNIT") {
    hdr.signalStrengthUnit = str(0, 20);
  } else if (lab == "RINEX VERSION / TYPE" && inFile) {
    // Not allowed inside the data section; ignored.
  }
  // Everything else (# OF SATELLITES, PRN / # OF OBS, WAVELENGTH FACT L1/2, ANTENNA: DELTA X/Y/Z,
  // ANTENNA: PHASECENTER, SYS / DCBS APPLIED, SYS / PCVS APPLIED, DOI, LICENSE OF USE, ...)
  // carries nothing the library uses and is tolerated.
}

/// SYS / # / OBS TYPES (RINEX 3): a system's observation types, continued on lines without a
/// system.
void RinexObsReader::Impl::obsTypesLine(std::string_view l, const TextLocation& w,
                                        const std::string& labStr) {
  const std::string_view s = column(l, 0, 1);
  if (!s.empty() && s[0] != ' ') {
    const auto sys = systemFromLetter(s[0]);
    if (!sys) fail(labStr, "unknown satellite system '" + std::string(s) + "'");
    lastTypesSystem = systemIndex(*sys);
    const long n = parseInt(column(l, 3, 3), w, labStr + " count");
    if (n < 0 || n > 999) fail(labStr + " count", "invalid number of types " + std::to_string(n));
    declaredTypes[lastTypesSystem] = static_cast<int>(n);
    rawTypes[lastTypesSystem].clear();
    typesChanged = true;
  } else if (lastTypesSystem < 0) {
    fail(labStr, "continuation line without a system");
  }
  auto& list = rawTypes[lastTypesSystem];
  for (int k = 0; k < 13; ++k) {
    const std::string_view t = trimmedColumn(l, 7 + 4 * k, 3);
    if (t.empty()) continue;
    if (static_cast<int>(list.size()) >= declaredTypes[lastTypesSystem]) {
      fail(labStr, "more types than the " + std::to_string(declaredTypes[lastTypesSystem]) + " declared");
    }
    list.emplace_back(t);
  }
}

/// # / TYPES OF OBSERV (RINEX 2): the observation types of all systems, continued on lines
/// without a count.
void RinexObsReader::Impl::rinex2TypesLine(std::string_view l, const TextLocation& w,
                                           const std::string& labStr) {
  const auto n = parseOptionalInt(column(l, 0, 6), w, labStr + " count");
  if (n) {
    if (*n < 0 || *n > 999) fail(labStr + " count", "invalid number of types " + std::to_string(*n));
    declaredR2Types = static_cast<int>(*n);
    hdr.rinex2Types.clear();
    typesChanged = true;
  } else if (declaredR2Types < 0) {
    fail(labStr, "continuation line without a count");
  }
  for (int k = 0; k < 9; ++k) {
    const std::string_view t = trimmedColumn(l, 10 + 6 * k, 2);
    if (t.empty()) continue;
    if (static_cast<int>(hdr.rinex2Types.size()) >= declaredR2Types) {
      fail(labStr, "more types than the " + std::to_string(declaredR2Types) + " declared");
    }
    hdr.rinex2Types.emplace_back(t);
  }
}

/// SYS / SCALE FACTOR: a factor for some of a system's types (all of them when none is listed).
void RinexObsReader::Impl::scaleFactorLine(std::string_view l, const TextLocation& w,
                                           const std::string& labStr) {
  const std::string_view s = column(l, 0, 1);
  if (!s.empty() && s[0] != ' ') {
    const auto sys = systemFromLetter(s[0]);
    if (!sys) fail(labStr, "unknown satellite system '" + std::string(s) + "'");
    lastScaleSystem = systemIndex(*sys);
    const long f = parseInt(column(l, 2, 4), w, labStr + " factor");
    if (f != 1 && f != 10 && f != 100 && f != 1000) {
      fail(labStr + " factor", "factor must be 1, 10, 100 or 1000, not " + std::to_string(f));
    }
    lastScaleFactor = static_cast<double>(f);
    const auto n = parseOptionalInt(column(l, 8, 2), w, labStr + " count");
    if (!n || *n == 0) scale[lastScaleSystem].emplace_back("", lastScaleFactor);
    typesChanged = true;
  } else if (lastScaleSystem < 0) {
    fail(labStr, "continuation line without a system");
  }
  for (int k = 0; k < 12; ++k) {
    const std::string_view t = trimmedColumn(l, 11 + 4 * k, 3);
    if (!t.empty()) scale[lastScaleSystem].emplace_back(std::string(t), lastScaleFactor);
  }
}

/// SYS / PHASE SHIFT: a phase correction of a system's signal and the satellites it applies to.
void RinexObsReader::Impl::phaseShiftLine(std::string_view l, const TextLocation& w,
                                          const std::string& labStr) {
  const std::string_view s = column(l, 0, 1);
  if (!s.empty() && s[0] != ' ') {
    const auto sys = systemFromLetter(s[0]);
    if (!sys) fail(labStr, "unknown satellite system '" + std::string(s) + "'");
    PhaseShiftRecord r;
    r.system = *sys;
    r.obs = ObsDescriptor::parse(trimmedColumn(l, 2, 3));
    r.cycles = parseOptionalDouble(column(l, 6, 8), w, labStr + " correction");
    hdr.phaseShifts.push_back(r);
    lastPhaseShift = &hdr.phaseShifts.back();
  }
  if (lastPhaseShift) {
    for (int k = 0; k < 10; ++k) {
      const std::string_view t = trimmedColumn(l, 19 + 4 * k, 3);
      if (t.empty()) continue;
      const auto sat = SatId::parse(t);
      if (!sat) fail(labStr + " satellite", "invalid satellite '" + std::string(t) + "'");
      lastPhaseShift->satellites.push_back(*sat);
    }
  }
}

/// GLONASS SLOT / FRQ #: FDMA channels of GLONASS slots.
void RinexObsReader::Impl::glonassSlotLine(std::string_view l, const TextLocation& w,
                                           const std::string& labStr) {
  const auto n = parseOptionalInt(column(l, 0, 3), w, labStr + " count");
  if (n) {
    declaredSlots = static_cast<int>(*n);
    slotCount = 0;
  }
  for (int k = 0; k < 8; ++k) {
    const std::string_view t = trimmedColumn(l, 4 + 7 * k, 3);
    if (t.empty()) continue;
    const auto sat = SatId::parse(t);
    if (!sat || sat->system != System::Glonass) {
      fail(labStr + " slot", "invalid GLONASS slot '" + std::string(t) + "'");
    }
    const long ch = parseInt(column(l, 8 + 7 * k, 2), w, labStr + " channel");
    if (ch < -7 || ch > 6) fail(labStr + " channel", "channel " + std::to_string(ch) + " outside -7..6");
    hdr.glonassChannels.set(sat->prn, static_cast<int>(ch));
    ++slotCount;
  }
}

/// GLONASS COD/PHS/BIS: code-phase biases.
void RinexObsReader::Impl::glonassBiasLine(std::string_view l, const TextLocation& w,
                                           const std::string& labStr) {
  for (int k = 0; k < 4; ++k) {
    const std::string_view t = trimmedColumn(l, 1 + 13 * k, 3);
    if (t.empty()) continue;
    const auto d = ObsDescriptor::parse(t);
    if (!d) fail(labStr, "invalid observation code '" + std::string(t) + "'");
    hdr.glonassBiases.push_back({*d, parseOptionalDouble(column(l, 5 + 13 * k, 8), w, labStr + " bias")});
  }
}

/// TIME OF FIRST OBS (with the time system) or TIME OF LAST OBS.
void RinexObsReader::Impl::observationTimeLine(std::string_view l, std::string_view lab, const TextLocation& w,
                                               const std::string& labStr) {
  CalendarTime c;
  c.year = static_cast<int>(parseInt(column(l, 0, 6), w, labStr + " year"));
  c.month = static_cast<int>(parseInt(column(l, 6, 6), w, labStr + " month"));
  c.day = static_cast<int>(parseInt(column(l, 12, 6), w, labStr + " day"));
  c.hour = static_cast<int>(parseInt(column(l, 18, 6), w, labStr + " hour"));
  c.minute = static_cast<int>(parseInt(column(l, 24, 6), w, labStr + " minute"));
  c.second = parseDouble(column(l, 30, 13), w, labStr + " second");
  if (!isValidCalendar(c) || c.year < 1980 || c.year > 2200) fail(labStr, "invalid date/time");
  const std::string ts(trimmedColumn(l, 48, 3));
  if (lab == "TIME OF FIRST OBS" && !ts.empty()) {
    if (ts != "GPS" && ts != "GLO" && ts != "GAL" && ts != "BDT" && ts != "QZS" && ts != "IRN") {
      fail(labStr + " time system", "unknown time system '" + ts + "'");
    }
    hdr.timeSystem = ts;
  }
  (lab == "TIME OF FIRST OBS" ? hdr.firstObs : hdr.lastObs) = epochTime(c);
}

void RinexObsReader::Impl::buildLayouts() {
  for (int s = 0; s < kNumSystems; ++s) {
    layout[s] = SystemLayout{};
    hdr.obsTypes[s].clear();
  }
  hdr.ignoredTypes.clear();
  auto addColumn = [&](int s, std::optional<ObsDescriptor> d, const std::string& raw) {
    SystemLayout& lay = layout[s];
    Column col;
    const System sys = static_cast<System>(s);
    if (d) {
      d->code = normalizeObsCode(sys, d->code, hdr.version);
      auto& list = hdr.obsTypes[s];
      if (std::find(list.begin(), list.end(), *d) != list.end()) {
        d.reset();  // duplicated column: the first one wins
      }
    }
    if (!d) {
      hdr.ignoredTypes.push_back(std::string(1, systemLetter(sys)) + " " + raw);
      lay.columns.push_back(col);
      return;
    }
    hdr.obsTypes[s].push_back(*d);
    auto it = std::find(lay.codes.begin(), lay.codes.end(), d->code);
    if (it == lay.codes.end()) {
      lay.codes.push_back(d->code);
      it = lay.codes.end() - 1;
    }
    col.signal = static_cast<int>(it - lay.codes.begin());
    col.type = d->type;
    for (const auto& [name, f] : scale[s]) {
      if (name.empty() || name == raw) col.scale = f;
    }
    lay.columns.push_back(col);
  };
  if (rinex2()) {
    if (declaredR2Types >= 0 && static_cast<int>(hdr.rinex2Types.size()) != declaredR2Types) {
      throwParseError({in.name(), in.lineNumber()}, "# / TYPES OF OBSERV",
                      std::to_string(declaredR2Types) + " types declared, " +
                          std::to_string(hdr.rinex2Types.size()) + " listed");
    }
    std::vector<System> systems;
    if (hdr.fileSystem == 'M') {
      for (int s = 0; s < kNumSystems; ++s) systems.push_back(static_cast<System>(s));
    } else {
      systems.push_back(*systemFromLetter(hdr.fileSystem));
    }
    for (System sys : systems) {
      for (const auto& t : hdr.rinex2Types) {
        addColumn(systemIndex(sys), rinex2ObsDescriptor(sys, t, hdr.rinex2Types), t);
      }
    }
  } else {
    for (int s = 0; s < kNumSystems; ++s) {
      if (static_cast<int>(rawTypes[s].size()) != declaredTypes[s]) {
        throwParseError({in.name(), in.lineNumber()}, "SYS / # / OBS TYPES",
                        std::string(1, systemLetter(static_cast<System>(s))) + ": " +
                            std::to_string(declaredTypes[s]) + " types declared, " +
                            std::to_string(rawTypes[s].size()) + " listed");
      }
      for (const auto& t : rawTypes[s]) addColumn(s, ObsDescriptor::parse(t), t);
    }
  }
  typesChanged = false;
}

GpsTime RinexObsReader::Impl::epochTime(const CalendarTime& c) const {
  if (hdr.timeSystem == "GLO") return glonassToGpst(c);
  GpsTime t = GpsTime::fromCalendar(c);
  if (hdr.timeSystem == "BDT") t -= kBdtMinusGpst;  // GPST = BDT + 14 s
  return t;
}

// ---------------------------------------------------------------------------------------------
// Epochs

bool RinexObsReader::Impl::looksLikeEpoch(std::string_view l) const {
  if (!rinex2()) return !l.empty() && l[0] == '>';
  // " YY MM DD HH MM SS.SSSSSSS  F NNN": blanks at fixed places, digits elsewhere, flag 0-6.
  if (l.size() < 29) return false;
  static constexpr int kBlank[] = {0, 3, 6, 9, 12};
  for (int b : kBlank) {
    if (l[b] != ' ') return false;
  }
  if (l[28] < '0' || l[28] > '6') return false;
  if (l[18] != '.' && !(l[28] >= '2' && l[28] <= '5')) return false;
  for (int i : {1, 2, 4, 5, 7, 8, 10, 11, 13, 14}) {
    if (l[i] != ' ' && (l[i] < '0' || l[i] > '9')) return false;
  }
  return true;
}

void RinexObsReader::Impl::resync() {
  while (in.next(line)) {
    if (looksLikeEpoch(line)) {
      in.unread();
      return;
    }
  }
}

void RinexObsReader::Impl::readSatValues(std::string_view l, std::size_t start, std::size_t /*perLine*/,
                                         SatObs& so, const SystemLayout& lay, std::size_t firstColumn,
                                         std::size_t count) {
  if (!l.empty() && l.back() == '\r') l.remove_suffix(1);
  for (std::size_t j = 0; j < count; ++j) {
    const std::size_t pos = start + 16 * j;
    if (pos >= l.size()) break;
    const std::size_t ci = firstColumn + j;
    if (ci >= lay.columns.size()) break;
    const Column& col = lay.columns[ci];
    if (col.signal < 0) continue;
    const std::string_view field = l.substr(pos, 16);
    const std::string_view num = field.substr(0, std::min<std::size_t>(14, field.size()));
    double v;
    const Fast f = fastDecimal(num, v);
    if (f == Fast::Blank) continue;
    if (f == Fast::Other) {
      if (isBlank(num)) continue;  // e.g. a trailing '\r'
      const std::string name = so.sat.str() + " " + ObsDescriptor(col.type, lay.codes[col.signal]).str();
      v = parseDouble(num, where(), name);
    }
    if (col.scale != 1.0) v /= col.scale;
    SignalObs& sig = so.signals[col.signal];
    const int slot = typeSlot(col.type);
    switch (col.type) {
      case ObsType::Code: sig.pseudorange = v; break;
      case ObsType::Phase: sig.carrierPhase = v; break;
      case ObsType::Doppler: sig.doppler = v; break;
      case ObsType::Snr: sig.snr = v; break;
    }
    sig.present |= kTypeBit[slot];
    if (field.size() > 14) {
      const char lli = field[14];
      if (lli >= '0' && lli <= '9') {
        sig.lli |= static_cast<std::uint8_t>(lli - '0');
      } else if (lli != ' ') {
        throwParseError(where(), so.sat.str() + " " + ObsDescriptor(col.type, lay.codes[col.signal]).str() + " LLI",
                        std::string("invalid loss-of-lock indicator '") + lli + "'");
      }
    }
    if (field.size() > 15) {
      const char ssi = field[15];
      if (ssi >= '0' && ssi <= '9') {
        ssiScratch[col.signal][slot] = static_cast<std::uint8_t>(ssi - '0');
      } else if (ssi != ' ') {
        throwParseError(where(), so.sat.str() + " " + ObsDescriptor(col.type, lay.codes[col.signal]).str() + " SSI",
                        std::string("invalid signal strength indicator '") + ssi + "'");
      }
    }
  }
}

void RinexObsReader::Impl::finishSat(SatObs& so, const SystemLayout& lay) {
  // SSI of the signal: the phase column's if phase is present, else the first present column
  // among code, Doppler, SNR (the writer puts it back in the same place).
  std::size_t out = 0;
  for (std::size_t k = 0; k < lay.codes.size(); ++k) {
    SignalObs& sig = so.signals[k];
    if (!sig.present) continue;
    static constexpr int kOrder[] = {1, 0, 2, 3};
    for (int slot : kOrder) {
      if (sig.present & kTypeBit[slot]) {
        sig.ssi = ssiScratch[k][slot];
        break;
      }
    }
    if (out != k) so.signals[out] = sig;
    ++out;
  }
  so.signals.resize(out);
}

bool RinexObsReader::Impl::readEpoch(ObsEpoch& e) {
  for (;;) {
    if (!in.next(line)) return false;
    if (isBlank(line)) continue;  // stray blank lines between epochs
    break;
  }
  epochLine = in.lineNumber();
  const std::string_view l = line;
  const bool r2 = rinex2();
  if (!r2 && l[0] != '>') fail("epoch record", "expected an epoch line starting with '>'");
  if (r2 && !looksLikeEpoch(l)) fail("epoch record", "malformed RINEX 2 epoch line");
  const std::size_t yearPos = r2 ? 1 : 2;
  const std::size_t flagPos = r2 ? 28 : 31;
  const std::size_t nsatPos = r2 ? 29 : 32;
  const auto flagV = parseOptionalInt(column(l, flagPos, 1), where(), "epoch flag");
  const int flag = flagV ? static_cast<int>(*flagV) : 0;
  if (flag < 0 || flag > 6) fail("epoch flag", "epoch flag " + std::to_string(flag) + " outside 0-6");
  const auto nV = parseOptionalInt(column(l, nsatPos, 3), where(), "number of satellites");
  const long nsat = nV.value_or(0);
  if (nsat < 0) fail("number of satellites", "negative count");

  // Date: blank allowed for event flags 2-5 (the event is then not time-tagged).
  const bool blankDate = isBlank(column(l, yearPos, r2 ? 25 : 27));
  const GpsTime t = blankDate && flag >= 2 && flag <= 5 ? (haveTime ? lastTime : GpsTime()) : epochLineTime(l);
  e.time = t;
  e.flag = static_cast<EpochFlag>(flag);
  e.receiverClockOffset.reset();

  if (flag >= 2 && flag <= 5) {
    readSpecialRecords(nsat);
    e.sats.clear();
    if (!blankDate) {
      lastTime = t;
      haveTime = true;
    }
    return true;
  }
  events.clear();
  // Receiver clock offset.
  {
    const std::string_view clk = r2 ? column(l, 68, 12) : column(l, 41, 15);
    e.receiverClockOffset = parseOptionalDouble(clk, where(), "receiver clock offset");
  }
  if (e.sats.size() < static_cast<std::size_t>(std::min<long>(nsat, 200))) {
    e.sats.resize(static_cast<std::size_t>(std::min<long>(nsat, 200)));
  }
  const std::size_t used = r2 ? readRinex2Satellites(e, nsat) : readRinex3Satellites(e, nsat);
  e.sats.resize(used);
  lastTime = t;
  haveTime = true;
  return true;
}

/// The date and time of an epoch line (RINEX 2 two-digit years: 1980-2079).
GpsTime RinexObsReader::Impl::epochLineTime(std::string_view l) const {
  const bool r2 = rinex2();
  const std::size_t yearPos = r2 ? 1 : 2, yearLen = r2 ? 2 : 4;
  const std::size_t monthPos = r2 ? 4 : 7;
  CalendarTime c;
  long y = parseInt(column(l, yearPos, yearLen), where(), "epoch year");
  if (r2) y += y < 80 ? 2000 : 1900;
  c.year = static_cast<int>(y);
  c.month = static_cast<int>(parseInt(column(l, monthPos, 2), where(), "epoch month"));
  c.day = static_cast<int>(parseInt(column(l, monthPos + 3, 2), where(), "epoch day"));
  c.hour = static_cast<int>(parseInt(column(l, monthPos + 6, 2), where(), "epoch hour"));
  c.minute = static_cast<int>(parseInt(column(l, monthPos + 9, 2), where(), "epoch minute"));
  c.second = parseDouble(column(l, monthPos + 11, 11), where(), "epoch second");
  if (!isValidCalendar(c) || c.year < 1980 || c.year > 2200) fail("epoch time", "invalid date/time");
  return epochTime(c);
}

/// The `nsat` special records of an event epoch (flags 2-5) into `events`; header records among
/// them update the header (and the column layouts when types change).
void RinexObsReader::Impl::readSpecialRecords(long nsat) {
  // Special records: header lines (new site, in-file header information, events).
  events.clear();
  for (long i = 0; i < nsat; ++i) {
    if (!in.next(line)) fail("special records", "file ends inside the records of an event epoch");
    if (!rinex2() && !line.empty() && line[0] == '>') {
      in.unread();
      fail("special records", "fewer special records than the " + std::to_string(nsat) + " announced");
    }
    events.emplace_back(line);
  }
  typesChanged = false;
  for (const auto& h : events) headerLine(h, label(h), true);
  if (typesChanged) buildLayouts();
}

/// The next satellite record of `e` (`used` of them so far), its signals laid out for its system.
SatObs& RinexObsReader::Impl::beginSat(ObsEpoch& e, std::size_t& used, SatId id, const SystemLayout& lay) {
  if (used >= e.sats.size()) e.sats.emplace_back();
  SatObs& so = e.sats[used++];
  so.sat = id;
  so.signals.resize(lay.codes.size());
  for (std::size_t k = 0; k < lay.codes.size(); ++k) so.signals[k] = SignalObs{lay.codes[k]};
  if (ssiScratch.size() < lay.codes.size()) ssiScratch.resize(lay.codes.size());
  for (std::size_t k = 0; k < lay.codes.size(); ++k) ssiScratch[k] = {0, 0, 0, 0};
  return so;
}

/// Counts and notes a satellite record that is skipped.
void RinexObsReader::Impl::skipSat(std::string_view id, const char* why) {
  ++stats.skippedSatellites;
  note("satellite '" + std::string(id) + "' skipped: " + why);
}

/// The satellite records of a RINEX 2 epoch (satellite list on the epoch line and its
/// continuation lines, then each satellite's values over lines of five); returns the number
/// of records filled in `e`.
std::size_t RinexObsReader::Impl::readRinex2Satellites(ObsEpoch& e, long nsat) {
  std::size_t used = 0;
  // Satellite list: 12 per line in columns 33-68, continuation lines for more.
  satLines.clear();
  satLines.emplace_back(line);
  for (long i = 12; i < nsat; i += 12) {
    if (!in.next(line)) fail("satellite list", "file ends inside the satellite list");
    satLines.emplace_back(line);
  }
  const std::size_t ntypes = hdr.rinex2Types.size();
  const std::size_t linesPerSat = ntypes == 0 ? 1 : (ntypes + 4) / 5;
  for (long i = 0; i < nsat; ++i) {
    const std::string_view sl = satLines[static_cast<std::size_t>(i / 12)];
    const std::string_view idText = column(sl, 32 + 3 * static_cast<std::size_t>(i % 12), 3);
    const auto id = SatId::parse(idText);
    const SystemLayout* lay = id ? &layout[systemIndex(id->system)] : nullptr;
    SatObs* so = nullptr;
    if (!id) {
      if (isBlank(idText)) fail("satellite list", "fewer satellites listed than the " + std::to_string(nsat) + " announced");
      skipSat(idText, "unknown system or satellite number");
    } else if (lay->columns.empty()) {
      skipSat(idText, "no observation types for its system");
    } else {
      so = &beginSat(e, used, *id, *lay);
    }
    for (std::size_t k = 0; k < linesPerSat; ++k) {
      if (!in.next(line)) fail("observation record", "file ends inside an epoch");
      if (so) readSatValues(line, 0, 5, *so, *lay, 5 * k, std::min<std::size_t>(5, ntypes - 5 * k));
    }
    if (so) finishSat(*so, *lay);
  }
  return used;
}

/// The satellite records of a RINEX 3/4 epoch (one line each, led by the satellite); returns
/// the number of records filled in `e`.
std::size_t RinexObsReader::Impl::readRinex3Satellites(ObsEpoch& e, long nsat) {
  std::size_t used = 0;
  for (long i = 0; i < nsat; ++i) {
    if (!in.next(line)) fail("observation record", "file ends inside an epoch (" + std::to_string(i) + " of " +
                                                       std::to_string(nsat) + " satellites read)");
    if (!line.empty() && line[0] == '>') {
      in.unread();
      fail("observation record", "epoch has " + std::to_string(i) + " satellite records, " +
                                     std::to_string(nsat) + " announced");
    }
    const std::string_view idText = column(line, 0, 3);
    std::optional<SatId> id;
    if (idText.size() == 3 && idText[1] >= '0' && idText[1] <= '9' && idText[2] >= '0' && idText[2] <= '9') {
      if (const auto sys = systemFromLetter(idText[0])) {
        const SatId q(*sys, (idText[1] - '0') * 10 + (idText[2] - '0'));
        if (q.valid()) id = q;
      }
    } else {
      id = SatId::parse(idText);
    }
    if (!id || (!idText.empty() && idText[0] == ' ')) {
      skipSat(idText, "unknown system or satellite number");
      continue;
    }
    const SystemLayout& lay = layout[systemIndex(id->system)];
    if (lay.columns.empty()) {
      skipSat(idText, "no observation types for its system");
      continue;
    }
    SatObs& so = beginSat(e, used, *id, lay);
    readSatValues(line, 3, lay.columns.size(), so, lay, 0, lay.columns.size());
    finishSat(so, lay);
  }
  return used;
}

// ---------------------------------------------------------------------------------------------

RinexObsReader::RinexObsReader(const std::string& path, RinexObsReaderOptions options)
    : impl_(std::make_unique<Impl>(LineReader(path, 8192), options)) {
  impl_->readHeader();
}

RinexObsReader::RinexObsReader(std::string_view text, std::string name, RinexObsReaderOptions options)
    : impl_(std::make_unique<Impl>(LineReader(text, std::move(name), 8192), options)) {
  impl_->readHeader();
}

RinexObsReader::~RinexObsReader() = default;
RinexObsReader::RinexObsReader(RinexObsReader&&) noexcept = default;
RinexObsReader& RinexObsReader::operator=(RinexObsReader&&) noexcept = default;

const RinexObsHeader& RinexObsReader::header() const { return impl_->hdr; }
const std::vector<std::string>& RinexObsReader::eventRecords() const { return impl_->events; }
const RinexObsReaderStats& RinexObsReader::stats() const { return impl_->stats; }
TextLocation RinexObsReader::location() const { return impl_->in.location(); }

bool RinexObsReader::next(ObsEpoch& epoch) {
  Impl& m = *impl_;
  for (;;) {
    bool got;
    if (m.opt.skipBadEpochs) {
      try {
        got = m.readEpoch(epoch);
      } catch (const ParseError& err) {
        ++m.stats.skippedEpochs;
        if (m.stats.messages.size() < m.opt.maxMessages) m.stats.messages.push_back(err.what());
        m.resync();
        continue;
      }
    } else {
      got = m.readEpoch(epoch);
    }
    if (!got) return false;
    const bool special = epoch.flag != EpochFlag::Ok && epoch.flag != EpochFlag::PowerFailure;
    if (special) {
      ++m.stats.specialRecords;
      if (!m.opt.returnSpecialRecords) continue;
      return true;
    }
    if (m.haveObsTime && !(epoch.time > m.lastObsTime)) {
      // Out of order, duplicated or restamped into the past: a solution for such an epoch would
      // come out of time order (RINEX epochs increase; RINEX 3.05 section 5.4).
      const std::string what = "epoch " + epoch.time.toString(3) + " GPST is " +
                               (epoch.time == m.lastObsTime ? "a repeat of" : "before") + " the previous epoch " +
                               m.lastObsTime.toString(3) + " (epochs must increase)";
      if (!m.opt.skipBadEpochs) throwParseError({m.in.name(), m.epochLine}, "epoch time", what);
      ++m.stats.skippedEpochs;
      ++m.stats.outOfOrderEpochs;
      if (m.stats.messages.size() < m.opt.maxMessages)
        m.stats.messages.push_back(m.in.name() + ":" + std::to_string(m.epochLine) + ": epoch time: " + what + "; skipped");
      continue;
    }
    m.lastObsTime = epoch.time;
    m.haveObsTime = true;
    ++m.stats.epochs;
    if (epoch.sats.empty()) ++m.stats.emptyEpochs;
    return true;
  }
}

std::vector<ObsEpoch> readRinexObs(const std::string& path, RinexObsHeader* header,
                                   RinexObsReaderOptions options) {
  RinexObsReader r(path, options);
  std::vector<ObsEpoch> out;
  ObsEpoch e;
  while (r.next(e)) out.push_back(e);
  if (header) *header = r.header();
  return out;
}

}  // namespace gvins
