// A gvins-spp run: the observation file epoch by epoch through the receiver checks (clock jumps,
// Doppler), the carrier smoothing and the SPP solver into the outputs, then the summary.
#pragma once

#include <chrono>

#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/gnss/spp_config.hpp"
#include "spp_options.hpp"

namespace gvins::sppapp {

/// Runs SPP over the observation file with the navigation data in `nav` (a UBX log adds to it);
/// `wall0` is the start of the run for the summary's time. Returns the exit status: 0, 1 on an
/// error (message printed), 3 when no epoch was solved.
int runSpp(const SppOptions& args, const SppConfig& cfg, EphemerisStore& nav, std::chrono::steady_clock::time_point wall0);

}  // namespace gvins::sppapp
