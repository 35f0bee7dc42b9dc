// gvins-spp: single point positioning (and Doppler velocity) from RINEX observation and
// navigation files or a UBX log, written as an RTKLIB-compatible .pos file. Options:
// spp_options.hpp; inputs: spp_inputs.hpp; the run: spp_run.hpp; outputs: spp_output.hpp;
// summary and --score: spp_summary.hpp.
#include <chrono>

#include "gvins/base/heap_pages.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "spp_inputs.hpp"
#include "spp_options.hpp"
#include "spp_run.hpp"
#include "spp_summary.hpp"

int main(int argc, char** argv) {
  using namespace gvins;
  keepHeapPages();
  const sppapp::SppOptions args = sppapp::parseSppOptions(argc, argv);
  const auto wall0 = std::chrono::steady_clock::now();
  if (!args.score.empty()) return sppapp::scorePosFile(args);
  const SppConfig cfg = sppapp::sppConfiguration(args);
  EphemerisStore nav;
  if (const int rc = sppapp::readNavigation(args, nav)) return rc;
  return sppapp::runSpp(args, cfg, nav, wall0);
}
