#include "gvins/base/rinex_obs_header.hpp"

#include <algorithm>
#include <cctype>

namespace gvins {

std::optional<ObsDescriptor> ObsDescriptor::parse(std::string_view three) {
  if (three.size() != 3) return std::nullopt;
  ObsType t;
  switch (three[0]) {
    case 'C': t = ObsType::Code; break;
    case 'L': t = ObsType::Phase; break;
    case 'D': t = ObsType::Doppler; break;
    case 'S': t = ObsType::Snr; break;
    default: return std::nullopt;
  }
  const auto code = ObsCode::parse(three.substr(1));
  if (!code) return std::nullopt;
  return ObsDescriptor(t, *code);
}

namespace {
bool listed(const std::vector<std::string>& all, std::string_view t) {
  return std::find(all.begin(), all.end(), t) != all.end();
}
}  // namespace

std::optional<ObsDescriptor> rinex2ObsDescriptor(System sys, std::string_view t,
                                                 const std::vector<std::string>& all) {
  // RINEX 2.11 (Gurtner & Estey 2007), section 5.1 and table A1: types C1 C2 P1 P2 L1 L2 D1 D2
  // S1 S2 (GPS/GLONASS), band numbers 5, 6, 7, 8 for L5/E5a, E6, E5b, E5a+b; T1/T2 are Transit.
  if (t.size() != 2) return std::nullopt;
  const char letter = t[0];
  const char band = t[1];
  if (!std::isdigit(static_cast<unsigned char>(band))) return std::nullopt;
  ObsType type;
  switch (letter) {
    case 'C':
    case 'P': type = ObsType::Code; break;
    case 'L': type = ObsType::Phase; break;
    case 'D': type = ObsType::Doppler; break;
    case 'S': type = ObsType::Snr; break;
    default: return std::nullopt;
  }
  auto has = [&](const char* x) { return listed(all, x); };
  char attr = 0;
  char b = band;
  switch (sys) {
    case System::Gps:
      if (band == '1') {
        if (letter == 'C') attr = 'C';
        else if (letter == 'P') attr = 'W';
        else attr = (has("C1") || !has("P1")) ? 'C' : 'W';
      } else if (band == '2') {
        if (letter == 'C') attr = 'X';  // L2C (RINEX 2.11 C2)
        else if (letter == 'P') attr = 'W';
        else attr = (has("P2") || !has("C2")) ? 'W' : 'X';
      } else if (band == '5') {
        if (letter != 'P') attr = 'X';
      }
      break;
    case System::Glonass:
      if (band == '1' || band == '2') {
        const char c[3] = {'C', band, 0}, p[3] = {'P', band, 0};
        if (letter == 'C') attr = 'C';
        else if (letter == 'P') attr = 'P';
        else if (band == '1') attr = (has(c) || !has(p)) ? 'C' : 'P';
        else attr = (has(p) || !has(c)) ? 'P' : 'C';
      }
      break;
    case System::Galileo:
      if (letter != 'P' && (band == '1' || band == '5' || band == '6' || band == '7' || band == '8')) {
        attr = 'X';
      }
      break;
    case System::Sbas:
      if (letter != 'P') {
        if (band == '1') attr = 'C';
        else if (band == '5') attr = 'X';
      }
      break;
    case System::Qzss:
      if (letter != 'P') {
        if (band == '1') attr = 'C';
        else if (band == '2' || band == '5' || band == '6') attr = 'X';
      }
      break;
    case System::BeiDou:
      // RINEX 2.12 draft: "1"/"2" both denoted B1 (1561.098 MHz), RINEX 3.03 band 2.
      if (letter != 'P') {
        if (band == '1' || band == '2') {
          b = '2';
          attr = 'I';
        } else if (band == '7' || band == '6') {
          attr = 'I';
        }
      }
      break;
    case System::Navic:
      if (letter != 'P' && (band == '5' || band == '9')) attr = 'A';
      break;
  }
  if (!attr) return std::nullopt;
  return ObsDescriptor(type, ObsCode(b, attr));
}

void RinexObsHeader::addTypesFrom(const ObsEpoch& epoch) {
  static constexpr std::pair<ObsType, std::uint8_t> kOrder[] = {{ObsType::Code, SignalObs::kCode},
                                                                {ObsType::Phase, SignalObs::kPhase},
                                                                {ObsType::Doppler, SignalObs::kDoppler},
                                                                {ObsType::Snr, SignalObs::kSnr}};
  for (const auto& so : epoch.sats) {
    auto& list = types(so.sat.system);
    for (const auto& sig : so.signals) {
      for (const auto& [type, bit] : kOrder) {
        if (!(sig.present & bit)) continue;
        const ObsDescriptor d(type, sig.code);
        if (std::find(list.begin(), list.end(), d) == list.end()) list.push_back(d);
      }
    }
  }
}

}  // namespace gvins
