#include "gvins/base/phase_alignment.hpp"

#include <initializer_list>
#include <string_view>

#include "gvins/base/rinex_obs_header.hpp"

namespace gvins {

const char* toString(PhaseAlignment a) {
  switch (a) {
    case PhaseAlignment::Unknown: return "unknown";
    case PhaseAlignment::Aligned: return "aligned";
    case PhaseAlignment::Raw: return "raw";
  }
  return "?";
}

PhaseAlignments PhaseAlignments::all(PhaseAlignment a) {
  PhaseAlignments p;
  p.bySystem.fill(a);
  return p;
}

double alignmentShift(System sys, ObsCode code) {
  // RINEX 3.04 Table A23 (see the header): {band, attributes, shift in cycles}.
  struct Row {
    char band;
    std::string_view attrs;
    double shift;
  };
  auto find = [&](std::initializer_list<Row> rows) {
    for (const Row& r : rows) {
      if (r.band == code.band && r.attrs.find(code.attr) != std::string_view::npos) return r.shift;
    }
    return 0.0;
  };
  switch (sys) {
    case System::Gps: return find({{'1', "PWNSLX", 0.25}, {'2', "CSLX", -0.25}, {'5', "Q", -0.25}});
    case System::Glonass: return find({{'1', "P", 0.25}, {'2', "P", 0.25}, {'3', "Q", 0.25}});
    case System::Galileo:
      return find({{'1', "C", 0.5}, {'5', "Q", -0.25}, {'7', "Q", -0.25}, {'8', "Q", -0.25}, {'6', "C", -0.5}});
    case System::Qzss: return find({{'1', "SLX", 0.25}, {'5', "QP", -0.25}});
    case System::BeiDou:
      return find({{'2', "Q", -0.25}, {'7', "Q", -0.25}, {'7', "P", 0.25}, {'6', "Q", -0.25}, {'1', "P", 0.25},
                   {'5', "P", 0.25}});
    case System::Sbas:
    case System::Navic: break;
  }
  return 0.0;
}

PhaseAlignments phaseAlignmentOf(const RinexObsHeader& header) {
  PhaseAlignments p;
  if (header.version < 3.01 - 1e-9) return p;
  for (const PhaseShiftRecord& r : header.phaseShifts) p.set(r.system, PhaseAlignment::Aligned);
  return p;
}

}  // namespace gvins
