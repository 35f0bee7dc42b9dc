// The inputs of gvins-spp: navigation files and precise products, SSR corrections and the
// observation file (RINEX or UBX).
#pragma once

#include <memory>

#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/gnss/base_reader.hpp"
#include "spp_options.hpp"

namespace gvins::sppapp {

/// Navigation files and precise products (told apart by name) into `nav`; 0 or an exit status
/// (message printed).
int readNavigation(const SppOptions& args, EphemerisStore& nav);

/// SSR corrections of --ssr into `nav`: their times of week resolve against the first
/// observation epoch. 0 or an exit status (message printed).
int readSsr(const SppOptions& args, EphemerisStore& nav);

/// The observation file: RINEX or UBX, told apart by content (BaseReader). A UBX log adds the
/// ephemerides of its RXM-SFRBX subframes to `nav` as they are read. Null (message printed) for
/// an RTCM log or a file that cannot be read.
std::unique_ptr<BaseReader> openObservations(const SppOptions& args, EphemerisStore& nav);

}  // namespace gvins::sppapp
