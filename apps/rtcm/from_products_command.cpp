// gvins-rtcm from-products NAV... SP3... [CLK...] [ATX...] -o FILE [--interval S] [--start T --end T]
// An SSR correction stream made from precise products, as a correction service would send it:
// combined orbit/clock messages (1060, 1066, 1243, 1249, 1261) every --interval seconds that turn
// the broadcast records a receiver holds into the products' states (gvins/ephemeris/
// ssr_from_products.hpp). For testing a real-time (SSR) processing chain against the products
// it is made from, e.g. `gvins-replay D --broadcast --ssr FILE` against `gvins-replay D`.
#include <algorithm>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>

#include "commands.hpp"
#include "gvins/base/atomic_output_file.hpp"
#include "gvins/base/command_line.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/ephemeris/precise_product_files.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/ephemeris/ssr_from_products.hpp"
#include "gvins/rtcm/ssr_file.hpp"
#include "stream_summary.hpp"

namespace gvins::rtcm_app {

int runFromProducts(int argc, char** argv) {
  std::string out;
  double interval = 5.0;
  std::vector<std::string> inputs;
  CommandLine cl("gvins-rtcm from-products", kUsage, argc, argv, 2);
  while (cl.next()) {
    if (cl.is("-o")) {
      out = cl.value();
    } else if (cl.is("--interval")) {
      const std::string v = cl.value();
      char* end = nullptr;
      interval = std::strtod(v.c_str(), &end);
      if (end == v.c_str() || *end != '\0' || !isSsrUpdateInterval(interval))
        cl.error("--interval must be an RTCM SSR update interval (1, 2, 5, 10, 15, 30, 60, ... 10800 s), not '" + v + "'");
    } else {
      inputs.push_back(cl.operand());
    }
  }
  if (out.empty()) cl.error("needs -o FILE");
  EphemerisStore nav;
  PreciseProductFiles products;
  for (const std::string& f : inputs)
    if (!products.add(f)) nav.add(readRinexNav(f));
  if (nav.size() == 0) cl.error("needs a navigation file (the broadcast records to correct)");
  if (products.orbits.empty()) cl.error("needs an SP3 orbit file");
  EphemerisStore productStore;
  auto precise = readPreciseProducts(products.orbits, products.clocks);
  const auto [first, last] = precise->span();
  productStore.setPrecise(std::move(precise));
  if (!products.antennas.empty()) productStore.setSatelliteAntennas(readAntennaFiles(products.antennas));
  if (!products.biases.empty())
    std::cerr << "gvins-rtcm: note: code biases are not turned into SSR code-bias messages (not implemented)\n";
  SsrServiceConfig service;
  service.interval = interval;
  const std::vector<SsrMessage> messages = ssrFromProducts(nav, productStore, first, last, service);
  if (messages.empty()) {
    std::string navFiles;
    for (const std::string& f : inputs)
      if (std::find(products.orbits.begin(), products.orbits.end(), f) == products.orbits.end() &&
          std::find(products.clocks.begin(), products.clocks.end(), f) == products.clocks.end() &&
          std::find(products.antennas.begin(), products.antennas.end(), f) == products.antennas.end() &&
          std::find(products.biases.begin(), products.biases.end(), f) == products.biases.end())
        navFiles += (navFiles.empty() ? "" : ", ") + f;
    throw std::runtime_error("from-products: no SSR correction: no satellite of the navigation file(s) " + navFiles +
                             " has a broadcast record usable in the products' span " + first.toString(0) + " to " +
                             last.toString(0) + " GPST (navigation and products of different days?)");
  }
  const std::vector<std::uint8_t> bytes = rtcm::encodeSsrFrames(messages);
  AtomicOutputFile file(out);
  file.stream().write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  file.commit();
  std::map<int, int> perType;
  std::size_t corrections = 0;
  for (const SsrMessage& m : messages) {
    ++perType[m.header.messageType];
    corrections += m.satellites.size();
  }
  std::cerr << "wrote " << out << ": " << messages.size() << " SSR messages (" << corrections
            << " satellite corrections, " << bytes.size() << " bytes), " << first.toString(0) << " to "
            << last.toString(0) << " GPST every " << interval << " s;";
  for (const auto& [type, n] : perType) std::cerr << " " << type << "x" << n;
  std::cerr << "\n";
  return 0;
}

}  // namespace gvins::rtcm_app
