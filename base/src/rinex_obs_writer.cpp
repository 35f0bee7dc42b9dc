// RINEX 3.04 observation writer (record formats of RINEX 3.04, tables A1-A3).
#include "gvins/base/rinex_obs_writer.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <ostream>

#include "gvins/base/parse_error.hpp"

namespace gvins {

namespace {

std::string fit(std::string_view s, std::size_t width) {
  std::string out(s.substr(0, std::min(s.size(), width)));
  out.resize(width, ' ');
  return out;
}

void headerLine(std::string& buf, std::string_view content, std::string_view label) {
  buf += fit(content, 60);
  buf += fit(label, 20);
  while (!buf.empty() && buf.back() == ' ') buf.pop_back();
  buf += '\n';
}

/// Calendar time of t rounded to 1e-7 s (the resolution of F11.7/F13.7 seconds), so that the
/// printed seconds never read 60.0000000.
CalendarTime roundedCalendar(const GpsTime& t) {
  const double f = std::round(t.fraction() * 1e7) / 1e7;
  return GpsTime::fromSeconds(t.wholeSeconds(), f).toCalendar();
}

/// printf("%w.df") if the value fits the width, else blanks (a RINEX field must never overflow
/// into its neighbour).
std::string fixed(double v, int width, int decimals) {
  char tmp[64];
  if (!std::isfinite(v) || std::abs(v) >= 1e15) return std::string(static_cast<std::size_t>(width), ' ');
  const int n = std::snprintf(tmp, sizeof tmp, "%*.*f", width, decimals, v);
  if (n != width) return std::string(static_cast<std::size_t>(width), ' ');
  return tmp;
}

bool fitsF14_3(double v) { return std::isfinite(v) && v > -999999999.9995 && v < 9999999999.9995; }

const std::uint8_t kBits[4] = {SignalObs::kCode, SignalObs::kPhase, SignalObs::kDoppler, SignalObs::kSnr};

int slotOf(ObsType t) {
  switch (t) {
    case ObsType::Code: return 0;
    case ObsType::Phase: return 1;
    case ObsType::Doppler: return 2;
    case ObsType::Snr: return 3;
  }
  return 0;
}

/// Column that carries a signal's LLI and SSI: phase when present, else the first present among
/// code, Doppler, SNR (mirrors the reader).
int flagSlot(const SignalObs& s) {
  if (s.present & SignalObs::kPhase) return 1;
  if (s.present & SignalObs::kCode) return 0;
  if (s.present & SignalObs::kDoppler) return 2;
  return 3;
}

}  // namespace

RinexObsWriter::RinexObsWriter(std::ostream& out, RinexObsHeader header, std::string_view programName)
    : out_(out), header_(std::move(header)), program_(programName) {
  header_.version = 3.04;
  if (header_.firstObs) writeHeader();
}

RinexObsWriter::~RinexObsWriter() {
  try {
    finish();
  } catch (...) {
  }
}

void RinexObsWriter::finish() {
  if (!headerWritten_) writeHeader();
  out_.flush();
}

void RinexObsWriter::writeHeader() {
  std::string b;
  char tmp[128];
  int nsys = 0;
  char onlySys = 'M';
  for (int s = 0; s < kNumSystems; ++s) {
    if (!header_.obsTypes[s].empty()) {
      ++nsys;
      onlySys = systemLetter(static_cast<System>(s));
    }
  }
  const char fileSys = nsys == 1 && onlySys == 'G' ? 'G' : 'M';
  std::snprintf(tmp, sizeof tmp, "%9.2f%11s%-20s%c", 3.04, "", "OBSERVATION DATA", fileSys);
  headerLine(b, tmp, "RINEX VERSION / TYPE");
  std::string date = header_.date;
  if (date.empty()) {
    const std::time_t now = std::time(nullptr);
    std::tm utc{};
    gmtime_r(&now, &utc);
    std::strftime(tmp, sizeof tmp, "%Y%m%d %H%M%S UTC", &utc);
    date = tmp;
  }
  headerLine(b, fit(header_.program.empty() ? program_ : header_.program, 20) + fit(header_.runBy, 20) + fit(date, 20),
             "PGM / RUN BY / DATE");
  for (const auto& c : header_.comments) headerLine(b, c, "COMMENT");
  const StationInfo& st = header_.station;
  headerLine(b, st.markerName.empty() ? "UNKNOWN" : st.markerName, "MARKER NAME");
  if (!st.markerNumber.empty()) headerLine(b, st.markerNumber, "MARKER NUMBER");
  if (!header_.markerType.empty()) headerLine(b, header_.markerType, "MARKER TYPE");
  headerLine(b, fit(header_.observer, 20) + fit(header_.agency, 40), "OBSERVER / AGENCY");
  headerLine(b, fit(st.receiverNumber, 20) + fit(st.receiverType, 20) + fit(st.receiverVersion, 20),
             "REC # / TYPE / VERS");
  headerLine(b, fit(st.antennaNumber, 20) + fit(st.antennaType, 20), "ANT # / TYPE");
  if (st.approxPosition) {
    const auto& p = *st.approxPosition;
    headerLine(b, fixed(p.x(), 14, 4) + fixed(p.y(), 14, 4) + fixed(p.z(), 14, 4), "APPROX POSITION XYZ");
  }
  headerLine(b, fixed(st.antennaDeltaHen[0], 14, 4) + fixed(st.antennaDeltaHen[1], 14, 4) +
                    fixed(st.antennaDeltaHen[2], 14, 4),
             "ANTENNA: DELTA H/E/N");
  for (int s = 0; s < kNumSystems; ++s) {
    const auto& list = header_.obsTypes[s];
    if (list.empty()) continue;
    std::string line;
    std::snprintf(tmp, sizeof tmp, "%c  %3d", systemLetter(static_cast<System>(s)), static_cast<int>(list.size()));
    line = tmp;
    for (std::size_t i = 0; i < list.size(); ++i) {
      if (i > 0 && i % 13 == 0) {
        headerLine(b, line, "SYS / # / OBS TYPES");
        line = "      ";
      }
      line += ' ';
      line += list[i].str();
    }
    headerLine(b, line, "SYS / # / OBS TYPES");
  }
  if (!header_.signalStrengthUnit.empty()) headerLine(b, header_.signalStrengthUnit, "SIGNAL STRENGTH UNIT");
  if (header_.interval) headerLine(b, fixed(*header_.interval, 10, 3), "INTERVAL");
  auto timeLine = [&](const GpsTime& t, const char* lab) {
    const CalendarTime c = roundedCalendar(t);
    std::snprintf(tmp, sizeof tmp, "%6d%6d%6d%6d%6d%13.7f     GPS", c.year, c.month, c.day, c.hour, c.minute,
                  c.second);
    headerLine(b, tmp, lab);
  };
  timeLine(header_.firstObs.value_or(GpsTime()), "TIME OF FIRST OBS");
  if (header_.lastObs) timeLine(*header_.lastObs, "TIME OF LAST OBS");
  if (header_.receiverClockOffsetApplied) headerLine(b, "     1", "RCV CLOCK OFFS APPL");
  for (const auto& ps : header_.phaseShifts) {
    std::string line(1, systemLetter(ps.system));
    line += ' ';
    line += ps.obs ? ps.obs->str() : "   ";
    line += ' ';
    line += ps.cycles ? fixed(*ps.cycles, 8, 5) : std::string(8, ' ');
    if (!ps.satellites.empty()) {
      std::snprintf(tmp, sizeof tmp, "  %2d", static_cast<int>(std::min<std::size_t>(ps.satellites.size(), 99)));
      line += tmp;
      for (std::size_t i = 0; i < ps.satellites.size(); ++i) {
        if (i > 0 && i % 10 == 0) {
          headerLine(b, line, "SYS / PHASE SHIFT");
          line = std::string(18, ' ');
        }
        line += ' ';
        line += ps.satellites[i].str();
      }
    }
    headerLine(b, line, "SYS / PHASE SHIFT");
  }
  if (header_.hasSystem(System::Glonass) || !header_.glonassChannels.empty()) {
    std::vector<std::pair<int, int>> slots;
    for (int s = 1; s <= 27; ++s) {
      if (const auto k = header_.glonassChannels.get(s)) slots.emplace_back(s, *k);
    }
    std::snprintf(tmp, sizeof tmp, "%3d ", static_cast<int>(slots.size()));
    std::string line = tmp;
    for (std::size_t i = 0; i < slots.size(); ++i) {
      if (i > 0 && i % 8 == 0) {
        headerLine(b, line, "GLONASS SLOT / FRQ #");
        line = "    ";
      }
      std::snprintf(tmp, sizeof tmp, "R%02d %2d ", slots[i].first, slots[i].second);
      line += tmp;
    }
    headerLine(b, line, "GLONASS SLOT / FRQ #");
    if (header_.hasSystem(System::Glonass)) {
      // RINEX 3.04 A2: mandatory for GLONASS; blank fields mean unknown.
      std::string bl;
      auto biases = header_.glonassBiases;
      if (biases.empty()) {
        for (const char* d : {"C1C", "C1P", "C2C", "C2P"}) biases.push_back({*ObsDescriptor::parse(d), std::nullopt});
      }
      for (std::size_t i = 0; i < biases.size(); ++i) {
        if (i > 0 && i % 4 == 0) {
          headerLine(b, bl, "GLONASS COD/PHS/BIS");
          bl.clear();
        }
        bl += ' ';
        bl += biases[i].obs.str();
        bl += ' ';
        bl += biases[i].bias ? fixed(*biases[i].bias, 8, 3) : std::string(8, ' ');
      }
      headerLine(b, bl, "GLONASS COD/PHS/BIS");
    }
  }
  if (header_.leapSeconds) {
    std::snprintf(tmp, sizeof tmp, "%6d", *header_.leapSeconds);
    headerLine(b, tmp, "LEAP SECONDS");
  }
  headerLine(b, "", "END OF HEADER");
  out_ << b;
  headerWritten_ = true;
}

void RinexObsWriter::write(const ObsEpoch& e, const std::vector<std::string>& eventRecords) {
  if (!headerWritten_) {
    if (!header_.firstObs) header_.firstObs = e.time;
    writeHeader();
  }
  const int flag = static_cast<int>(e.flag);
  buf_.clear();
  char tmp[64];
  int count = 0;
  std::string body;
  if (flag >= 2 && flag <= 5) {
    for (const auto& r : eventRecords) {
      if (count >= 999) break;
      std::string l = fit(r, 80);
      std::string_view lab = std::string_view(l).substr(60);  // trimmed as RinexObsReader reads it
      while (!lab.empty() && lab.back() == ' ') lab.remove_suffix(1);
      while (!lab.empty() && lab.front() == ' ') lab.remove_prefix(1);
      if (lab == "SYS / # / OBS TYPES" || lab == "SYS / SCALE FACTOR" || lab == "# / TYPES OF OBSERV" ||
          lab == "WAVELENGTH FACT L1/2" || lab == "RINEX VERSION / TYPE" || lab == "END OF HEADER") {
        ++droppedRecords_;
        continue;
      }
      if (l[0] == '>') l[0] = ' ';  // would read as an epoch line
      while (!l.empty() && l.back() == ' ') l.pop_back();
      body += l;
      body += '\n';
      ++count;
    }
  } else {
    for (const SatObs& so : e.sats) {
      const auto& types = header_.types(so.sat.system);
      if (types.empty() || !so.sat.valid()) {
        for (const auto& s : so.signals) dropped_ += std::popcount(static_cast<unsigned>(s.present & 15));
        continue;
      }
      std::string line = so.sat.str();
      for (const ObsDescriptor& d : types) {
        const SignalObs* s = so.find(d.code);
        const int slot = slotOf(d.type);
        if (!s || !(s->present & kBits[slot])) {
          line.append(16, ' ');
          continue;
        }
        double v = 0.0;
        switch (d.type) {
          case ObsType::Code: v = s->pseudorange; break;
          case ObsType::Phase: v = s->carrierPhase; break;
          case ObsType::Doppler: v = s->doppler; break;
          case ObsType::Snr: v = s->snr; break;
        }
        if (!fitsF14_3(v)) {
          ++dropped_;
          line.append(16, ' ');
          continue;
        }
        std::snprintf(tmp, sizeof tmp, "%14.3f", v);
        line += tmp;
        const bool flags = slot == flagSlot(*s);
        line += flags && s->lli ? static_cast<char>('0' + std::min<int>(s->lli, 9)) : ' ';
        line += flags && s->ssi ? static_cast<char>('0' + std::min<int>(s->ssi, 9)) : ' ';
      }
      // Values of signals that have no column.
      for (const auto& s : so.signals) {
        for (int slot = 0; slot < 4; ++slot) {
          if (!(s.present & kBits[slot])) continue;
          const ObsDescriptor d(slot == 0 ? ObsType::Code : slot == 1 ? ObsType::Phase : slot == 2 ? ObsType::Doppler : ObsType::Snr,
                                s.code);
          if (std::find(types.begin(), types.end(), d) == types.end()) ++dropped_;
        }
      }
      while (line.size() > 3 && line.back() == ' ') line.pop_back();
      body += line;
      body += '\n';
      ++count;
    }
  }
  const CalendarTime c = roundedCalendar(e.time);
  std::snprintf(tmp, sizeof tmp, "> %4d %02d %02d %02d %02d%11.7f  %1d%3d", c.year, c.month, c.day, c.hour, c.minute,
                c.second, flag, std::min(count, 999));
  buf_ = tmp;
  if (e.receiverClockOffset && flag != 2 && flag != 3 && flag != 4 && flag != 5) {
    const std::string clk = fixed(*e.receiverClockOffset, 15, 12);
    if (clk[14] != ' ') buf_ += "      " + clk;
  }
  buf_ += '\n';
  buf_ += body;
  out_ << buf_;
  ++epochs_;
}

void writeRinexObs(const std::string& path, const RinexObsHeader& header, const std::vector<ObsEpoch>& epochs) {
  std::ofstream f(path);
  if (!f) throw ParseError(path, 0, "", "cannot create file");
  RinexObsWriter w(f, header);
  for (const auto& e : epochs) w.write(e);
  w.finish();
  if (!f) throw ParseError(path, 0, "", "write error");
}

}  // namespace gvins
