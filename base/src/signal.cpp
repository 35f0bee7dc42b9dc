#include "gvins/base/signal.hpp"

#include <algorithm>
#include <cctype>

#include "gvins/base/constants.hpp"

namespace gvins {

std::optional<ObsCode> ObsCode::parse(std::string_view two) {
  if (two.size() != 2) return std::nullopt;
  if (!std::isdigit(static_cast<unsigned char>(two[0]))) return std::nullopt;
  if (!std::isalpha(static_cast<unsigned char>(two[1]))) return std::nullopt;
  return ObsCode(two[0], two[1]);
}

namespace {
// Nominal carrier frequencies, Hz.
// GPS: IS-GPS-200 (L1 154*f0, L2 120*f0), IS-GPS-705 (L5 115*f0), f0 = 10.23 MHz.
// Galileo: OS SIS ICD 2.1 table 2 (E1, E6, E5, E5a, E5b).
// BeiDou: BDS-SIS-ICD B1I 3.0 (1561.098), B1C 1.0, B2a 1.0, B3I 1.0 (1268.52), B2b/B2I 1207.14.
// GLONASS CDMA: ICD L3OC (1202.025), L1OC (1600.995), L2OC (1248.06).
// QZSS: IS-QZSS-PNT (L1, L2, L5) and IS-QZSS-L6 (1278.75). NavIC: ISRO IRNSS SPS ICD (L5, S).
constexpr double kF0 = 10.23e6;
constexpr double kL1 = 154 * kF0, kL2 = 120 * kF0, kL5 = 115 * kF0;
constexpr double kE6 = 125 * kF0, kE5b = 118 * kF0, kE5 = 116.5 * kF0;
constexpr double kB1I = 152.6 * kF0, kB3 = 124 * kF0;
}  // namespace

bool isKnownBand(System sys, char band) { return carrierFrequency(sys, band, 0).has_value(); }

std::optional<double> carrierFrequency(System sys, char band, std::optional<int> k) {
  switch (sys) {
    case System::Gps:
      if (band == '1') return kL1;
      if (band == '2') return kL2;
      if (band == '5') return kL5;
      break;
    case System::Qzss:
      if (band == '1') return kL1;
      if (band == '2') return kL2;
      if (band == '5') return kL5;
      if (band == '6') return kE6;
      break;
    case System::Sbas:
      if (band == '1') return kL1;
      if (band == '5') return kL5;
      break;
    case System::Galileo:
      if (band == '1') return kL1;
      if (band == '5') return kL5;
      if (band == '7') return kE5b;
      if (band == '8') return kE5;
      if (band == '6') return kE6;
      break;
    case System::BeiDou:
      if (band == '2') return kB1I;
      if (band == '1') return kL1;
      if (band == '5') return kL5;
      if (band == '7') return kE5b;
      if (band == '8') return kE5;
      if (band == '6') return kB3;
      break;
    case System::Glonass:
      if (band == '1' || band == '2') {
        if (!k || *k < -7 || *k > 6) return std::nullopt;
        return band == '1' ? 1602.0e6 + *k * 0.5625e6 : 1246.0e6 + *k * 0.4375e6;
      }
      if (band == '3') return 117.5 * kF0;  // 1202.025 MHz
      if (band == '4') return 1600.995e6;
      if (band == '6') return 1248.06e6;
      break;
    case System::Navic:
      if (band == '5') return kL5;
      if (band == '9') return 2492.028e6;
      if (band == '1') return kL1;
      break;
  }
  return std::nullopt;
}

std::optional<double> carrierWavelength(System sys, char band, std::optional<int> k) {
  const auto f = carrierFrequency(sys, band, k);
  if (!f) return std::nullopt;
  return constants::kSpeedOfLight / *f;
}

ObsCode normalizeObsCode(System sys, ObsCode code, double rinexVersion) {
  if (sys == System::BeiDou && code.band == '1' && rinexVersion < 3.025 &&
      (code.attr == 'I' || code.attr == 'Q' || code.attr == 'X')) {
    return ObsCode('2', code.attr);
  }
  return code;
}

std::string_view attributePriority(System sys, char band) {
  // Orders in the spirit of common receiver practice: civil open signals first, then combined
  // (X), then semi-codeless.
  switch (sys) {
    case System::Gps:
      if (band == '1') return "CSLXPWYM";
      if (band == '2') return "CDSLXPWYM";
      if (band == '5') return "IQX";
      break;
    case System::Glonass:
      if (band == '1' || band == '2') return "CP";
      if (band == '3') return "IQX";
      if (band == '4' || band == '6') return "ABX";
      break;
    case System::Galileo:
      if (band == '1') return "CABXZ";
      if (band == '5' || band == '7' || band == '8') return "IQX";
      if (band == '6') return "ABCXZ";
      break;
    case System::BeiDou:
      if (band == '2' || band == '7' || band == '6') return "IQXDPZ";
      if (band == '1' || band == '5' || band == '8') return "DPXSLZ";
      break;
    case System::Qzss:
      if (band == '1') return "CSLXZEB";
      if (band == '2') return "SLX";
      if (band == '5') return "IQXDPZ";
      if (band == '6') return "SLXEZ";
      break;
    case System::Sbas:
      if (band == '1') return "C";
      if (band == '5') return "IQX";
      break;
    case System::Navic:
      return "ABCX";
  }
  return "";
}

namespace {

// Attributes of a band grouped by transmitted signal, groups separated by '|'.
std::string_view signalGroups(System sys, char band) {
  switch (sys) {
    case System::Gps:
      if (band == '1') return "C|SLX|PWYND|M";
      if (band == '2') return "C|SLX|PWYND|M";
      if (band == '5') return "IQX";
      break;
    case System::Glonass:
      if (band == '1' || band == '2') return "C|P";
      if (band == '3') return "IQX";
      if (band == '4' || band == '6') return "ABX";
      break;
    case System::Galileo:
      if (band == '1' || band == '6') return "BCX|AZ";
      if (band == '5' || band == '7' || band == '8') return "IQX";
      break;
    case System::BeiDou:
      if (band == '2') return "IQX";
      if (band == '1') return "DPX|SLZ";
      if (band == '5' || band == '8') return "DPX";
      if (band == '7' || band == '6') return "IQX|DPZ";
      break;
    case System::Qzss:
      if (band == '1') return "C|SLX|Z|EB";
      if (band == '2') return "SLX";
      if (band == '5') return "IQX|DPZ";
      if (band == '6') return "SLX|EZ";
      break;
    case System::Sbas:
      if (band == '1') return "C";
      if (band == '5') return "IQX";
      break;
    case System::Navic:
      return "A|BCX";
  }
  return "";
}

}  // namespace

bool sameSignal(System sys, ObsCode a, ObsCode b) {
  if (a.band != b.band) return false;
  if (a.attr == b.attr) return true;
  const std::string_view g = signalGroups(sys, a.band);
  const auto pa = g.find(a.attr), pb = g.find(b.attr);
  if (pa == std::string_view::npos || pb == std::string_view::npos) return false;
  const auto lo = std::min(pa, pb), hi = std::max(pa, pb);
  return g.substr(lo, hi - lo).find('|') == std::string_view::npos;
}

char primaryBand(System sys) {
  switch (sys) {
    case System::BeiDou: return '2';
    case System::Navic: return '5';
    default: return '1';
  }
}

}  // namespace gvins
