#include "spp_inputs.hpp"

#include <cstdio>
#include <string>

#include "gvins/base/parse_error.hpp"
#include "gvins/ephemeris/precise_product_files.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/rtcm/ssr_file.hpp"

namespace gvins::sppapp {

int readNavigation(const SppOptions& args, EphemerisStore& nav) {
  try {
    PreciseProductFiles products;
    for (std::size_t i = 1; i < args.inputs.size(); ++i) {
      if (!products.add(args.inputs[i])) nav.add(readRinexNav(args.inputs[i]));
    }
    if (!products.antennas.empty()) nav.setSatelliteAntennas(readAntennaFiles(products.antennas));
    if (!products.biases.empty()) nav.setCodeBiases(readCodeBiasFiles(products.biases));
    if (products.orbits.empty() && !products.clocks.empty()) {
      std::fprintf(stderr, "gvins-spp: error: clock files need an SP3 orbit file\n");
      return 2;
    }
    if (!products.orbits.empty()) {
      auto precise = readPreciseProducts(products.orbits, products.clocks);
      if (!args.quiet) std::fprintf(stderr, "precise products: %zu satellites\n", precise->satellites().size());
      nav.setPrecise(std::move(precise));
    }
  } catch (const ParseError& e) {
    printSppError(e.what());
    return 1;
  }
  return 0;
}

int readSsr(const SppOptions& args, EphemerisStore& nav) {
  GpsTime first;
  try {
    auto peek = BaseReader::open(args.inputs[0], GpsTime{}, nullptr, !args.strict);
    ObsEpoch e;
    if (peek->next(e)) first = e.time;
  } catch (const ParseError& e) {
    printSppError(e.what());
    return 1;
  }
  try {
    std::size_t n = 0;
    for (const std::string& f : args.ssr) {
      const rtcm::SsrFile ssr = rtcm::readSsrFile(f, first);
      for (const SsrMessage& m : ssr.messages) nav.addSsr(m);
      n += ssr.messages.size();
      if (ssr.stats.malformed > 0 && !args.quiet)
        std::fprintf(stderr, "%s: %lld malformed RTCM frames skipped\n", f.c_str(),
                     static_cast<long long>(ssr.stats.malformed));
    }
    if (!args.quiet) std::fprintf(stderr, "SSR corrections: %zu messages\n", n);
  } catch (const ParseError& e) {
    printSppError(e.what());
    return 1;
  }
  return 0;
}

std::unique_ptr<BaseReader> openObservations(const SppOptions& args, EphemerisStore& nav) {
  try {
    if (BaseReader::detect(args.inputs[0]) == BaseFormat::Rtcm) {
      std::fprintf(stderr, "gvins-spp: error: %s is an RTCM 3 log; convert it with gvins-rtcm to-rinex --date first\n",
                   args.inputs[0].c_str());
      return nullptr;
    }
    return BaseReader::open(args.inputs[0], GpsTime{}, &nav, !args.strict);
  } catch (const ParseError& e) {
    printSppError(e.what());
    return nullptr;
  }
}

}  // namespace gvins::sppapp
