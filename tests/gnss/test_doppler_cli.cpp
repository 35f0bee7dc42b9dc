// gvins-spp and gvins-rtk on RINEX copies of the Nagoya receivers with the Doppler sign flipped:
// one warning per signal on stderr, the verdicts in the summary, and the same solutions (.pos rows)
// as the unflipped copies.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "gvins/base/rinex_obs_reader.hpp"
#include "gvins/base/rinex_obs_writer.hpp"

using namespace gvins;

namespace {

const std::string kData = GVINS_TEST_DATA;
const std::string kDir = kData + "/gnss/nagoya_static_2024/";

std::string tmp(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("gvins_doppler_cli_" + std::to_string(::getpid()) + "_" + name)).string();
}

std::string readAll(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

/// Exit code and stderr of a tool run.
std::pair<int, std::string> run(const std::string& tool, const std::string& args) {
  const std::string err = tmp(tool + ".err");
  const int rc = std::system((std::string(GVINS_BIN_DIR) + "/" + tool + " -q " + args + " 2>" + err + " >/dev/null").c_str());
  std::string text = readAll(err);
  std::filesystem::remove(err);
  return {WEXITSTATUS(rc), text};
}

/// The solution rows of a .pos file (header comments left out: they name the input files).
std::vector<std::string> rows(const std::string& path) {
  std::vector<std::string> out;
  std::ifstream f(path);
  for (std::string l; std::getline(f, l);) {
    if (!l.empty() && l[0] != '%') out.push_back(l);
  }
  return out;
}

/// Writes the receiver's epochs as RINEX, with the Doppler of `only` (all signals if empty)
/// negated when `flip`.
std::string writeCopy(const std::string& in, const std::string& name, bool flip, const std::string& only = {}) {
  RinexObsHeader h;
  std::vector<ObsEpoch> epochs = readRinexObs(kDir + in, &h);
  if (flip) {
    for (ObsEpoch& e : epochs) {
      for (SatObs& so : e.sats) {
        for (SignalObs& s : so.signals) {
          const std::string n{systemLetter(so.sat.system), s.code.band, s.code.attr};
          if (s.hasDoppler() && (only.empty() || n == only)) s.doppler = -s.doppler;
        }
      }
    }
  }
  const std::string path = tmp(name);
  writeRinexObs(path, h, epochs);
  return path;
}

std::size_t countOf(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

}  // namespace

TEST(DopplerCli, FlippedCopiesGiveTheOriginalSolutionsWithWarnings) {
  const std::string rover = writeCopy("rover.obs.gz", "rover.obs", false);
  const std::string base = writeCopy("base.obs.gz", "base.obs", false);
  const std::string roverFlipped = writeCopy("rover.obs.gz", "rover_flipped.obs", true);
  const std::string baseFlipped = writeCopy("base.obs.gz", "base_flipped.obs", true, "G2W");
  const std::string nav = kDir + "base.nav.gz";

  // SPP: 15 warnings, the summary's counters, and the rows of the unflipped copy.
  const std::string truth = " --truth-llh 35.13469901,136.97757549,104.8626";
  const auto [c0, e0] = run("gvins-spp", "-o " + tmp("a.pos") + truth + " " + rover + " " + nav);
  const auto [c1, e1] = run("gvins-spp", "-o " + tmp("b.pos") + truth + " " + roverFlipped + " " + nav);
  ASSERT_EQ(c0, 0) << e0;
  ASSERT_EQ(c1, 0) << e1;
  // No Doppler warning on the original (the signal-choice notice of the receiver's BeiDou satellites
  // without B1I is another matter).
  EXPECT_EQ(countOf(e0, "warning: rover: Doppler"), 0u) << e0;
  EXPECT_EQ(countOf(e0, "warning"), countOf(e0, "warning: BeiDou: B1I not tracked")) << e0;
  EXPECT_EQ(countOf(e1, "gvins-spp: warning: rover: Doppler sign flipped on "), 15u) << e1;
  EXPECT_NE(e1.find("gvins-spp: warning: rover: Doppler sign flipped on G L1C (corrected)\n"), std::string::npos) << e1;
  EXPECT_NE(e1.find("  Doppler                0 passed, 44627 corrected, 0 dropped, 462 withheld (undecided)\n"),
            std::string::npos)
      << e1;
  EXPECT_NE(e1.find("    rover: Doppler sign flipped on G L1C (corrected; 36 samples, 12 satellites"), std::string::npos)
      << e1;
  EXPECT_NE(e0.find("  Doppler                44627 passed, 0 corrected, 0 dropped, 462 withheld (undecided)\n"),
            std::string::npos)
      << e0;
  EXPECT_NE(e1.find("velocity error vs truth (298 epochs, m/s)"), std::string::npos) << e1;
  const auto a = rows(tmp("a.pos")), b = rows(tmp("b.pos"));
  EXPECT_EQ(a.size(), 301u);
  EXPECT_EQ(a, b);

  // RTK: the rover flipped on every signal, the base on GPS L2W only.
  const std::string opt = " --base-llh 35.134707705,136.977577939,104.853 ";
  const auto [r0, f0] = run("gvins-rtk", "-o " + tmp("c.pos") + opt + rover + " " + base + " " + nav);
  const auto [r1, f1] = run("gvins-rtk", "-o " + tmp("d.pos") + opt + roverFlipped + " " + baseFlipped + " " + nav);
  ASSERT_EQ(r0, 0) << f0;
  ASSERT_EQ(r1, 0) << f1;
  EXPECT_EQ(countOf(f1, "gvins-rtk: warning: rover: Doppler sign flipped on "), 15u) << f1;
  EXPECT_EQ(countOf(f1, "gvins-rtk: warning: base: Doppler sign flipped on G L2W (corrected)\n"), 1u) << f1;
  EXPECT_EQ(countOf(f1, "gvins-rtk: warning:"), 16u) << f1;
  EXPECT_NE(f1.find("fix rate                 100.00 % of epochs"), std::string::npos) << f1;
  EXPECT_NE(f1.find("rover slips             LLI 10, geometry-free 8, Doppler 0,"), std::string::npos) << f1;
  EXPECT_NE(f1.find("base  slips             LLI 8, geometry-free 10, Doppler 0,"), std::string::npos) << f1;
  const auto c = rows(tmp("c.pos")), d = rows(tmp("d.pos"));
  EXPECT_EQ(c.size(), 301u);
  EXPECT_EQ(c, d);
  for (const std::string& f : {rover, base, roverFlipped, baseFlipped, tmp("a.pos"), tmp("b.pos"), tmp("c.pos"), tmp("d.pos")})
    std::filesystem::remove(f);
}
