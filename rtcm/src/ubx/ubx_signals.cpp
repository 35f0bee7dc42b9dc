#include "gvins/ubx/ubx_signals.hpp"

namespace gvins::ubx {

namespace {

struct SignalEntry {
  std::uint8_t gnssId, sigId;
  ObsCode code;
  std::string_view name;
};

// u-blox ZED-F9P HPG 1.32 / X20 HPG 2.00 interface descriptions, "Signal identifiers"; RINEX
// 3.05 tables 4-10 for the attributes (BeiDou B1I is band 2 from RINEX 3.03 on).
constexpr SignalEntry kSignals[] = {
    {0, 0, {'1', 'C'}, "GPS L1C/A"},        {0, 3, {'2', 'L'}, "GPS L2 CL"},
    {0, 4, {'2', 'S'}, "GPS L2 CM"},        {0, 6, {'5', 'I'}, "GPS L5 I"},
    {0, 7, {'5', 'Q'}, "GPS L5 Q"},         {1, 0, {'1', 'C'}, "SBAS L1C/A"},
    {2, 0, {'1', 'C'}, "Galileo E1 C"},     {2, 1, {'1', 'B'}, "Galileo E1 B"},
    {2, 3, {'5', 'I'}, "Galileo E5a I"},    {2, 4, {'5', 'Q'}, "Galileo E5a Q"},
    {2, 5, {'7', 'I'}, "Galileo E5b I"},    {2, 6, {'7', 'Q'}, "Galileo E5b Q"},
    {2, 8, {'6', 'B'}, "Galileo E6 B"},     {2, 9, {'6', 'C'}, "Galileo E6 C"},
    {2, 10, {'6', 'A'}, "Galileo E6 A"},    {3, 0, {'2', 'I'}, "BeiDou B1I D1"},
    {3, 1, {'2', 'I'}, "BeiDou B1I D2"},    {3, 2, {'7', 'I'}, "BeiDou B2I D1"},
    {3, 3, {'7', 'I'}, "BeiDou B2I D2"},    {3, 4, {'6', 'I'}, "BeiDou B3I D1"},
    {3, 10, {'6', 'I'}, "BeiDou B3I D2"},   {3, 5, {'1', 'P'}, "BeiDou B1C pilot"},
    {3, 6, {'1', 'D'}, "BeiDou B1C data"},  {3, 7, {'5', 'P'}, "BeiDou B2a pilot"},
    {3, 8, {'5', 'D'}, "BeiDou B2a data"},  {5, 0, {'1', 'C'}, "QZSS L1C/A"},
    {5, 1, {'1', 'Z'}, "QZSS L1S"},         {5, 4, {'2', 'S'}, "QZSS L2 CM"},
    {5, 5, {'2', 'L'}, "QZSS L2 CL"},       {5, 8, {'5', 'I'}, "QZSS L5 I"},
    {5, 9, {'5', 'Q'}, "QZSS L5 Q"},        {6, 0, {'1', 'C'}, "GLONASS L1 OF"},
    {6, 2, {'2', 'C'}, "GLONASS L2 OF"},    {7, 0, {'5', 'A'}, "NavIC L5 A"},
};

const SignalEntry* findSignal(std::uint8_t gnssId, std::uint8_t sigId) {
  for (const auto& e : kSignals) {
    if (e.gnssId == gnssId && e.sigId == sigId) return &e;
  }
  return nullptr;
}

}  // namespace

std::optional<System> systemOfGnssId(std::uint8_t gnssId) {
  switch (gnssId) {
    case 0: return System::Gps;
    case 1: return System::Sbas;
    case 2: return System::Galileo;
    case 3: return System::BeiDou;
    case 5: return System::Qzss;
    case 6: return System::Glonass;
    case 7: return System::Navic;
    default: return std::nullopt;  // 4 = IMES and reserved values
  }
}

std::optional<SatId> satelliteOf(std::uint8_t gnssId, std::uint8_t svId) {
  const auto sys = systemOfGnssId(gnssId);
  if (!sys) return std::nullopt;
  int prn = svId;
  if (*sys == System::Sbas) prn -= 100;  // PRN 120..158 -> S20..S58
  // QZSS svId is 1..10 already (PRN - 192); GLONASS svId 255 means an unknown slot.
  const SatId s(*sys, prn);
  if (prn < 0 || !s.valid()) return std::nullopt;
  return s;
}

std::optional<ObsCode> obsCodeOf(std::uint8_t gnssId, std::uint8_t sigId) {
  const SignalEntry* e = findSignal(gnssId, sigId);
  if (!e) return std::nullopt;
  return e->code;
}

std::string_view signalName(std::uint8_t gnssId, std::uint8_t sigId) {
  const SignalEntry* e = findSignal(gnssId, sigId);
  return e ? e->name : std::string_view("?");
}

}  // namespace gvins::ubx
