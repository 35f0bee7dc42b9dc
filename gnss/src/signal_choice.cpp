#include "gvins/gnss/signal_choice.hpp"

#include <algorithm>

namespace gvins {

std::string_view fallbackBands(System sys) {
  switch (sys) {
    case System::Gps:
    case System::Qzss: return "152";
    case System::Glonass: return "123";
    case System::Galileo: return "15786";
    case System::BeiDou: return "267158";
    case System::Sbas: return "15";
    case System::Navic: return "59";
  }
  return "";
}

std::string bandsWithFallback(std::string_view preferred, System sys) {
  std::string out(preferred);
  for (char band : fallbackBands(sys)) {
    if (out.find(band) == std::string::npos) out.push_back(band);
  }
  return out;
}

std::string bandName(System sys, char band) {
  switch (sys) {
    case System::Gps:
    case System::Qzss:
    case System::Sbas:
      if (band == '1' || band == '2' || band == '5' || band == '6') return std::string("L") + band;
      break;
    case System::Glonass:
      if (band == '1' || band == '2' || band == '3') return std::string("G") + band;
      if (band == '4') return "G1a";
      if (band == '6') return "G2a";
      break;
    case System::Galileo:
      switch (band) {
        case '1': return "E1";
        case '5': return "E5a";
        case '7': return "E5b";
        case '8': return "E5";
        case '6': return "E6";
        default: break;
      }
      break;
    case System::BeiDou:
      switch (band) {
        case '2': return "B1I";
        case '1': return "B1C";
        case '5': return "B2a";
        case '7': return "B2I/B2b";
        case '8': return "B2";
        case '6': return "B3I";
        default: break;
      }
      break;
    case System::Navic:
      if (band == '5') return "L5";
      if (band == '9') return "S";
      break;
  }
  return std::string("band ") + band;
}

std::optional<CodeSignal> primaryCode(const SatObs& so, std::string_view preferred, std::size_t count,
                                      std::optional<int> glonassChannel) {
  const std::size_t n = std::min(count, preferred.size());
  for (std::size_t i = 0; i < n; ++i) {
    if (auto c = usableCode(so, preferred[i], glonassChannel)) return c;
  }
  for (std::size_t i = n; i < preferred.size(); ++i) {
    if (auto c = usableCode(so, preferred[i], glonassChannel)) return c;
  }
  for (char band : fallbackBands(so.sat.system)) {
    if (preferred.find(band) != std::string_view::npos) continue;
    if (auto c = usableCode(so, band, glonassChannel)) return c;
  }
  return std::nullopt;
}

std::optional<std::string> SignalFallbackNotices::record(System sys, char preferredBand, ObsCode used) {
  if (used.band == preferredBand) return std::nullopt;
  if (!seen_.insert({static_cast<int>(sys), used.str()}).second) return std::nullopt;
  std::string m = std::string(systemName(sys)) + ": " + bandName(sys, preferredBand) + " not tracked, using " +
                  bandName(sys, used.band) + " (" + systemLetter(sys) + used.str() + ")";
  messages_.push_back(m);
  return m;
}

}  // namespace gvins
