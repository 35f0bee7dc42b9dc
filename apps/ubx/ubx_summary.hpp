// Shared pieces of the gvins-ubx commands: decoding a whole input, the summary table.
#pragma once

#include <cstdio>
#include <ostream>
#include <string>
#include <vector>

#include "gvins/ubx/ubx_decoder.hpp"

namespace gvins::ubx_app {

/// Feeds a whole input through the decoder in chunks; `onItem` gets every decoded item.
template <class F>
void decodeAll(std::FILE* in, ubx::Decoder& dec, F&& onItem) {
  std::vector<std::uint8_t> buf(1 << 16);
  for (;;) {
    const std::size_t n = std::fread(buf.data(), 1, buf.size(), in);
    if (n > 0) dec.feed({buf.data(), n});
    while (auto item = dec.poll()) onItem(*item);
    if (n < buf.size()) break;
  }
  dec.finish();
  while (auto item = dec.poll()) onItem(*item);
}

/// What the summary shows besides the decoder's counters.
struct SummaryExtras {
  std::int64_t navPvt = 0, navPvtFixes = 0;
  std::optional<ubx::NavPvt> lastPvt;
  std::optional<ubx::NavClock> lastClock;
};

/// "RXM-RAWX" etc. for the messages a receiver commonly sends; "" otherwise.
std::string_view messageName(int type);

/// SFRBX navigation messages per gnssId/sigId (BeiDou GEO apart): what each carries, whether it
/// is decoded, records, check failures and unknown pages.
void printNavigationSources(std::ostream& out, const ubx::NavigationAssembler& nav);

/// Per-message table, other protocols, time span, signals per system, errors.
void printSummary(std::ostream& out, const ubx::Decoder& dec, const SummaryExtras& extras, const std::string& name);

}  // namespace gvins::ubx_app
