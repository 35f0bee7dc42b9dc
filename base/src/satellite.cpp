#include "gvins/base/satellite.hpp"

#include <array>
#include <cctype>

namespace gvins {

char systemLetter(System s) {
  static constexpr char kLetters[] = {'G', 'R', 'E', 'C', 'J', 'S', 'I'};
  return kLetters[systemIndex(s)];
}

std::optional<System> systemFromLetter(char c) {
  switch (c) {
    case 'G': return System::Gps;
    case 'R': return System::Glonass;
    case 'E': return System::Galileo;
    case 'C': return System::BeiDou;
    case 'J': return System::Qzss;
    case 'S': return System::Sbas;
    case 'I': return System::Navic;
    default: return std::nullopt;
  }
}

std::string_view systemName(System s) {
  static constexpr std::string_view kNames[] = {"GPS", "GLONASS", "Galileo", "BeiDou",
                                                "QZSS", "SBAS", "NavIC"};
  return kNames[systemIndex(s)];
}

std::string SatId::str() const {
  std::string out(3, '0');
  out[0] = systemLetter(system);
  out[1] = static_cast<char>('0' + prn / 10);
  out[2] = static_cast<char>('0' + prn % 10);
  return out;
}

std::optional<SatId> SatId::parse(std::string_view text) {
  while (!text.empty() && text.back() == ' ') text.remove_suffix(1);
  while (!text.empty() && text.front() == ' ' && text.size() > 1 &&
         !std::isdigit(static_cast<unsigned char>(text[1])) && text[1] != ' ') {
    text.remove_prefix(1);
  }
  if (text.empty()) return std::nullopt;
  System sys = System::Gps;
  std::size_t i = 0;
  if (std::isalpha(static_cast<unsigned char>(text[0]))) {
    const auto s = systemFromLetter(text[0]);
    if (!s) return std::nullopt;
    sys = *s;
    i = 1;
  }
  while (i < text.size() && text[i] == ' ') ++i;
  if (i >= text.size() || text.size() - i > 3) return std::nullopt;
  int n = 0;
  for (; i < text.size(); ++i) {
    if (!std::isdigit(static_cast<unsigned char>(text[i]))) return std::nullopt;
    n = n * 10 + (text[i] - '0');
  }
  // RINEX 2 SBAS / QZSS numbers are sometimes written as the full PRN (e.g. S120, J193).
  if (sys == System::Sbas && n >= 120) n -= 100;
  if (sys == System::Qzss && n >= 193) n -= 192;
  SatId id(sys, n);
  if (n > 255 || !id.valid()) return std::nullopt;
  return id;
}

namespace {
constexpr std::array<int, kNumSystems + 1> offsets() {
  std::array<int, kNumSystems + 1> o{};
  for (int s = 0; s < kNumSystems; ++s) {
    const System sys = static_cast<System>(s);
    o[s + 1] = o[s] + maxPrn(sys) - minPrn(sys) + 1;
  }
  return o;
}
constexpr auto kOffsets = offsets();
}  // namespace

int satIndex(SatId s) { return kOffsets[systemIndex(s.system)] + s.prn - minPrn(s.system); }

SatId satFromIndex(int index) {
  for (int s = kNumSystems - 1; s >= 0; --s) {
    if (index >= kOffsets[s]) {
      const System sys = static_cast<System>(s);
      return SatId(sys, index - kOffsets[s] + minPrn(sys));
    }
  }
  return {};
}

int numSatIndices() { return kOffsets[kNumSystems]; }

BeiDouOrbit beidouOrbit(int prn) {
  if (prn <= 5 || prn >= 59) return BeiDouOrbit::Geo;
  switch (prn) {
    case 6: case 7: case 8: case 9: case 10: case 13: case 16: case 31: case 38: case 39:
    case 40: case 56:
      return BeiDouOrbit::Igso;
    default:
      return BeiDouOrbit::Meo;
  }
}

}  // namespace gvins
