// Differencing across tracking modes of one band (RtkConfig::signalMatching, PhaseAlignment).
//
// Real data: the Nagoya pair (two Septentrio mosaic-X5, RINEX 3.04 with SYS / PHASE SHIFT
// records). The base file is rewritten as a receiver of another brand would have written it: GPS
// L2 L -> X, L2 W -> P, L5 Q -> X; Galileo E1 C -> X, E5a/E5b Q -> X; BeiDou B1I/B2I/B3I I -> X;
// QZSS L2 L -> X, L5 Q -> X, in the observation types and in the phase shift records. The phase
// values stay: RINEX 3.01+ phases are consistent with the band's reference signal whatever mode
// was tracked (RINEX 3.04, phase cycle shifts, Table A23), so the rewritten file is what such a
// converter would write. The independent truth is the original pair: band matching on the
// rewritten pair must give the same satellites, fixes and positions; strict matching must lose
// the rewritten signals.
//
// Raw tracking phases (PhaseAlignment::Raw) are checked the same way: base phases de-aligned by
// the Table A23 shift on half of the GPS satellites must, once declared raw, give the original
// solution again, and declared aligned (the shift ignored) must not.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "gvins/base/geodetic.hpp"
#include "gvins/base/line_reader.hpp"
#include "gvins/base/parse_error.hpp"
#include "gvins/base/phase_alignment.hpp"
#include "gvins/base/rinex_obs_reader.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/gnss/base_reader.hpp"
#include "gvins/gnss/rtk.hpp"
#include "gvins/gnss/rtk_config.hpp"
#include "gvins/rtcm/encoder.hpp"
#include "nagoya_pair.hpp"

using namespace gvins;

namespace {

const std::string kData = GVINS_TEST_DATA;
const std::string kDir = kData + "/gnss/nagoya_static_2024/";

// Base codes of another receiver brand: system letter, original code, rewritten code.
struct CodeMap {
  char sys;
  const char* from;
  const char* to;
};
constexpr CodeMap kRewrite[] = {{'G', "2L", "2X"}, {'G', "2W", "2P"}, {'G', "5Q", "5X"}, {'E', "1C", "1X"},
                                {'E', "5Q", "5X"}, {'E', "7Q", "7X"}, {'C', "2I", "2X"}, {'C', "7I", "7X"},
                                {'C', "6I", "6X"}, {'J', "2L", "2X"}, {'J', "5Q", "5X"}};

std::string mapped(char sys, std::string_view code2) {
  for (const CodeMap& m : kRewrite) {
    if (m.sys == sys && code2 == m.from) return m.to;
  }
  return std::string(code2);
}

// The base RINEX text with the observation types and phase shift records rewritten (kRewrite).
std::string rewrittenBaseText() {
  LineReader in(kDir + "base.obs.gz");
  std::string out, line;
  bool header = true;
  char typesSys = ' ';
  while (in.next(line)) {
    if (header && line.size() >= 80) {
      const std::string label = line.substr(60, 20);
      if (label.rfind("SYS / # / OBS TYPES", 0) == 0) {
        if (line[0] != ' ') typesSys = line[0];
        for (std::size_t c = 7; c + 3 <= 58; c += 4) {
          if (line[c] == ' ') continue;
          line.replace(c + 1, 2, mapped(typesSys, line.substr(c + 1, 2)));
        }
      } else if (label.rfind("SYS / PHASE SHIFT", 0) == 0) {
        line.replace(3, 2, mapped(line[0], line.substr(3, 2)));
      } else if (label.rfind("END OF HEADER", 0) == 0) {
        header = false;
      }
    }
    out += line;
    out += '\n';
  }
  return out;
}

struct Pair {
  std::vector<ObsEpoch> rover, base, rewritten;
  RinexObsHeader roverHeader, baseHeader, rewrittenHeader;
  EphemerisStore nav;
  Eigen::Vector3d basePosition = Eigen::Vector3d::Zero();
};  // the recorded pair (tests/support/nagoya_pair.hpp) and the base rewritten

const Pair& nagoya() {
  static const Pair p = [] {
    Pair s;
    const test::RecordedPair& d = test::nagoyaPair();
    s.rover = d.rover;
    s.roverHeader = d.roverHeader;
    s.base = d.base;
    s.baseHeader = d.baseHeader;
    const std::string text = rewrittenBaseText();  // the reader keeps a view of it
    RinexObsReader r(text, "base.obs (rewritten)");
    ObsEpoch e;
    while (r.next(e)) s.rewritten.push_back(e);
    s.rewrittenHeader = r.header();
    s.nav = d.nav;
    s.basePosition = d.basePosition;
    return s;
  }();
  return p;
}

struct Outcome {
  std::vector<RtkSolution> sol;
  std::vector<std::set<SatId>> phaseSats;  // satellites with a DD phase, per epoch
  std::int64_t sdCount = 0;                // SDs formed
  std::map<std::pair<System, char>, std::int64_t> sdPerGroup;
  DdFormationStats stats;
  int fixed() const {
    return static_cast<int>(std::count_if(sol.begin(), sol.end(), [](const RtkSolution& s) { return s.quality == SolutionQuality::Fix; }));
  }
};

Outcome run(const std::vector<ObsEpoch>& base, const PhaseAlignments& roverAlign, const PhaseAlignments& baseAlign,
        SignalMatching matching, int epochs) {
  const Pair& p = nagoya();
  RtkConfig cfg;
  cfg.signalMatching = matching;
  RtkSolver s(p.nav, cfg);
  s.setRoverGlonassChannels(p.roverHeader.glonassChannels);
  s.setBaseGlonassChannels(p.baseHeader.glonassChannels);
  s.setBasePosition(p.basePosition);
  s.setPhaseAlignment(roverAlign, baseAlign);
  Outcome r;
  std::size_t b = 0;
  for (int i = 0; i < epochs; ++i) {
    const ObsEpoch& e = p.rover[static_cast<std::size_t>(i)];
    while (b < base.size() && (b == 0 || base[b - 1].time - e.time <= BaseStation::kSyncTolerance)) s.addBaseEpoch(base[b++]);
    r.sol.push_back(s.process(e));
    const DdEpoch& dd = s.measurements();
    std::set<SatId> sats;
    for (const DoubleDifference& d : dd.phase) {
      sats.insert(dd.sd[static_cast<std::size_t>(d.reference)].sat);
      sats.insert(dd.sd[static_cast<std::size_t>(d.satellite)].sat);
    }
    r.phaseSats.push_back(sats);
    r.sdCount += static_cast<std::int64_t>(dd.sd.size());
    for (const SingleDifference& d : dd.sd) ++r.sdPerGroup[{d.sat.system, d.code.band}];
  }
  r.stats = s.differenceStats();
  return r;
}

bool rewrittenSystemBand(System s, char band) {
  for (const CodeMap& m : kRewrite) {
    if (systemFromLetter(m.sys) == s && m.from[0] == band) return true;
  }
  return false;
}

double maxDifference(const Outcome& a, const Outcome& b) {
  double m = 0.0;
  for (std::size_t i = 0; i < a.sol.size(); ++i) m = std::max(m, (a.sol[i].position - b.sol[i].position).norm());
  return m;
}

}  // namespace

TEST(PhaseAlignment, RinexHeaderAndTableA23) {
  const Pair& p = nagoya();
  // RINEX 3.04 with SYS / PHASE SHIFT records for G, R, E, C, J.
  const PhaseAlignments a = phaseAlignmentOf(p.baseHeader);
  for (System s : {System::Gps, System::Glonass, System::Galileo, System::BeiDou, System::Qzss}) {
    EXPECT_EQ(a.get(s), PhaseAlignment::Aligned) << systemName(s);
  }
  EXPECT_EQ(a.get(System::Sbas), PhaseAlignment::Unknown);
  EXPECT_EQ(phaseAlignmentOf(p.rewrittenHeader).get(System::Galileo), PhaseAlignment::Aligned);
  RinexObsHeader old = p.baseHeader;
  old.version = 3.00;  // before phase cycle shifts were defined
  EXPECT_EQ(phaseAlignmentOf(old).get(System::Gps), PhaseAlignment::Unknown);
  old.version = 3.04;
  old.phaseShifts.clear();  // no record: the converter states nothing
  EXPECT_EQ(phaseAlignmentOf(old).get(System::Gps), PhaseAlignment::Unknown);

  // RINEX 3.04 Table A23.
  EXPECT_EQ(alignmentShift(System::Gps, ObsCode('1', 'C')), 0.0);
  EXPECT_EQ(alignmentShift(System::Gps, ObsCode('1', 'W')), 0.25);
  EXPECT_EQ(alignmentShift(System::Gps, ObsCode('2', 'L')), -0.25);
  EXPECT_EQ(alignmentShift(System::Gps, ObsCode('2', 'W')), 0.0);
  EXPECT_EQ(alignmentShift(System::Gps, ObsCode('5', 'Q')), -0.25);
  EXPECT_EQ(alignmentShift(System::Galileo, ObsCode('1', 'C')), 0.5);
  EXPECT_EQ(alignmentShift(System::Galileo, ObsCode('1', 'B')), 0.0);
  EXPECT_EQ(alignmentShift(System::Galileo, ObsCode('7', 'Q')), -0.25);
  EXPECT_EQ(alignmentShift(System::Glonass, ObsCode('2', 'P')), 0.25);
  EXPECT_EQ(alignmentShift(System::BeiDou, ObsCode('7', 'Q')), -0.25);
  EXPECT_EQ(alignmentShift(System::BeiDou, ObsCode('7', 'P')), 0.25);

  // Modes of one signal vs different signals of a band.
  EXPECT_TRUE(sameSignal(System::Gps, ObsCode('2', 'L'), ObsCode('2', 'X')));
  EXPECT_FALSE(sameSignal(System::Gps, ObsCode('2', 'L'), ObsCode('2', 'W')));
  EXPECT_FALSE(sameSignal(System::Gps, ObsCode('1', 'C'), ObsCode('1', 'X')));
  EXPECT_TRUE(sameSignal(System::Galileo, ObsCode('1', 'C'), ObsCode('1', 'X')));
  EXPECT_FALSE(sameSignal(System::Galileo, ObsCode('1', 'C'), ObsCode('5', 'C')));
}

TEST(SignalMatching, YamlKey) {
  EXPECT_EQ(RtkConfig{}.signalMatching, SignalMatching::Band);
  EXPECT_EQ(parseRtkConfig("rtk: {signal_matching: strict}\n", "t.yaml").signalMatching, SignalMatching::Strict);
  RtkConfig strict;
  strict.signalMatching = SignalMatching::Strict;
  EXPECT_EQ(parseRtkConfig("rtk: {signal_matching: band}\n", "t.yaml", strict).signalMatching, SignalMatching::Band);
  try {
    parseRtkConfig("rtk:\n  signal_matching: loose\n", "t.yaml");
    FAIL() << "no error";
  } catch (const ParseError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("t.yaml"), std::string::npos) << w;
    EXPECT_NE(w.find("signal_matching"), std::string::npos) << w;
    EXPECT_NE(w.find("loose"), std::string::npos) << w;
  }
}

// The rewritten base against the original: same satellites, fixes and positions (within 1 mm)
// with band matching; strict matching loses exactly the rewritten groups.
TEST(SignalMatching, OtherTrackingModesAtTheBase) {
  const Pair& p = nagoya();
  const PhaseAlignments rover = phaseAlignmentOf(p.roverHeader);
  const int n = static_cast<int>(p.rover.size());
  ASSERT_EQ(n, 301);
  const Outcome orig = run(p.base, rover, phaseAlignmentOf(p.baseHeader), SignalMatching::Band, n);
  const Outcome band = run(p.rewritten, rover, phaseAlignmentOf(p.rewrittenHeader), SignalMatching::Band, n);
  EXPECT_GE(orig.fixed(), 298);
  EXPECT_EQ(orig.stats.crossMode, 0);
  EXPECT_EQ(band.fixed(), orig.fixed());
  EXPECT_EQ(band.phaseSats, orig.phaseSats);
  EXPECT_EQ(band.sdCount, orig.sdCount);
  EXPECT_LT(maxDifference(band, orig), 1e-3);
  for (std::size_t i = 0; i < orig.sol.size(); ++i) EXPECT_EQ(band.sol[i].quality, orig.sol[i].quality) << i;
  // Every SD of a rewritten system and band went across modes.
  std::int64_t rewrittenSds = 0;
  for (const auto& [g, c] : orig.sdPerGroup) {
    if (rewrittenSystemBand(g.first, g.second)) rewrittenSds += c;
  }
  EXPECT_GT(rewrittenSds, 5000);
  EXPECT_EQ(band.stats.crossMode, rewrittenSds);
  EXPECT_EQ(band.stats.signalMismatch, orig.stats.signalMismatch);

  // Strict: the rewritten groups are gone (Galileo and BeiDou entirely: all their bands).
  const int m = 60;
  const Outcome strict = run(p.rewritten, rover, phaseAlignmentOf(p.rewrittenHeader), SignalMatching::Strict, m);
  EXPECT_EQ(strict.stats.crossMode, 0);
  std::int64_t strictRewritten = 0;
  for (const auto& [g, c] : strict.sdPerGroup) {
    if (rewrittenSystemBand(g.first, g.second)) strictRewritten += c;
  }
  EXPECT_EQ(strictRewritten, 0);
  EXPECT_GT(strict.stats.crossModeRefused, 0);
  int lost = 0;
  for (int i = 0; i < m; ++i) {
    std::set<SatId> expect;
    for (SatId s : orig.phaseSats[static_cast<std::size_t>(i)]) {
      if (s.system != System::Galileo && s.system != System::BeiDou) expect.insert(s);
    }
    EXPECT_EQ(strict.phaseSats[static_cast<std::size_t>(i)], expect) << i;
    lost += static_cast<int>(orig.phaseSats[static_cast<std::size_t>(i)].size() - expect.size());
  }
  EXPECT_GT(lost, 10 * m);  // Galileo + BeiDou: more than 10 satellites per epoch

  // Unknown alignment at the base (e.g. RINEX 3.00): as strict, pairs refused and counted.
  const Outcome unknown = run(p.rewritten, rover, PhaseAlignments{}, SignalMatching::Band, m);
  EXPECT_EQ(unknown.stats.crossMode, 0);
  EXPECT_EQ(unknown.stats.crossModeRefused, strict.stats.crossModeRefused);
  EXPECT_EQ(unknown.phaseSats, strict.phaseSats);
}

// Raw tracking phases at the base: the even GPS satellites report P(Y) on L1 ("1W", a quarter
// cycle off the C/A reference, Table A23) instead of C/A, the odd ones C/A; one DD group mixes
// both. Declared raw, the shift is restored and the original solution comes back; declared
// aligned, the quarter cycle stays in the DDs between even and odd satellites.
TEST(SignalMatching, RawTrackingPhasesAreAligned) {
  const Pair& p = nagoya();
  std::vector<ObsEpoch> raw = p.base;
  int renamed = 0;
  for (ObsEpoch& e : raw) {
    for (SatObs& so : e.sats) {
      if (so.sat.system != System::Gps) continue;
      for (SignalObs& s : so.signals) {
        if (so.sat.prn % 2 == 0 && s.code == ObsCode('1', 'C')) {
          s.code = ObsCode('1', 'W');
          ++renamed;
        }
        if (s.hasPhase()) s.carrierPhase -= alignmentShift(System::Gps, s.code);  // tracked = aligned - shift
      }
    }
  }
  ASSERT_GT(renamed, 1000);
  const PhaseAlignments rover = phaseAlignmentOf(p.roverHeader);
  PhaseAlignments baseRaw = phaseAlignmentOf(p.baseHeader);
  baseRaw.set(System::Gps, PhaseAlignment::Raw);
  const int n = 120;
  const Outcome orig = run(p.base, rover, phaseAlignmentOf(p.baseHeader), SignalMatching::Band, n);
  const Outcome corrected = run(raw, rover, baseRaw, SignalMatching::Band, n);
  EXPECT_EQ(corrected.fixed(), orig.fixed());
  EXPECT_EQ(corrected.phaseSats, orig.phaseSats);
  EXPECT_LT(maxDifference(corrected, orig), 1e-3);
  EXPECT_GT(corrected.stats.crossMode, 0);

  const Outcome ignored = run(raw, rover, phaseAlignmentOf(p.baseHeader), SignalMatching::Band, n);
  EXPECT_TRUE(ignored.fixed() < orig.fixed() || maxDifference(ignored, orig) > 3e-3)
      << ignored.fixed() << " fixed, " << maxDifference(ignored, orig) << " m";
}

// The rewritten base streamed as RTCM 3 MSM7 (the project's encoder): MSM phases are aligned
// (RTCM 10403.3), the reader says so for every system it decoded MSM of, and the solution is the
// original pair's (MSM7 resolution: within 2 mm, as RtkNagoya.RtcmBaseStreamGivesTheSameSolution).
TEST(SignalMatching, RtcmMsmBaseOfOtherTrackingModes) {
  const Pair& p = nagoya();
  const int n = 40;
  const auto path = std::filesystem::temp_directory_path() / "gvins_test_signal_matching.rtcm3";
  {
    std::ofstream out(path, std::ios::binary);
    rtcm::Encoder enc(7);
    enc.setGlonassChannels(p.baseHeader.glonassChannels);
    for (int i = 0; i < n; ++i) {
      const auto f = enc.msm(p.rewritten[static_cast<std::size_t>(i)], 7);
      out.write(reinterpret_cast<const char*>(f.data()), static_cast<std::streamsize>(f.size()));
    }
  }
  EphemerisStore nav = p.nav;
  auto reader = BaseReader::open(path.string(), p.rover.front().time, &nav);
  EXPECT_EQ(reader->phaseAlignment().get(System::Galileo), PhaseAlignment::Unknown);  // nothing decoded yet
  std::vector<ObsEpoch> base;
  ObsEpoch e;
  while (reader->next(e)) base.push_back(e);
  std::filesystem::remove(path);
  ASSERT_EQ(base.size(), static_cast<std::size_t>(n));
  const PhaseAlignments a = reader->phaseAlignment();
  for (System s : {System::Gps, System::Glonass, System::Galileo, System::BeiDou, System::Qzss}) {
    EXPECT_EQ(a.get(s), PhaseAlignment::Aligned) << systemName(s);
  }
  EXPECT_EQ(a.get(System::Sbas), PhaseAlignment::Unknown);
  const PhaseAlignments rover = phaseAlignmentOf(p.roverHeader);
  const Outcome orig = run(p.base, rover, phaseAlignmentOf(p.baseHeader), SignalMatching::Band, n);
  const Outcome msm = run(base, rover, a, SignalMatching::Band, n);
  EXPECT_EQ(msm.fixed(), n);
  EXPECT_EQ(msm.phaseSats, orig.phaseSats);
  EXPECT_GT(msm.stats.crossMode, 1000);
  EXPECT_LT(maxDifference(msm, orig), 0.002);
}
