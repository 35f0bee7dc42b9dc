// Example consumer of an installed SRI-GVINS (SriGvins::rtcm): an RTCM 3 log decoded into
// observation epochs.
//
//   rtcm_decode FILE [YYYY-MM-DD]
//
// The date (GPST, within a few days of the data) resolves the weeks of the messages' times of week;
// without it the decoder uses the host clock until the stream gives an absolute time. Prints the
// frames per message type, the observation epochs (count, first and last time, satellites in the
// first epoch and in all epochs), the ephemerides and the station position.
#include <cstdint>
#include <cstdio>
#include <exception>
#include <fstream>
#include <iterator>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include <gvins/rtcm/decoder.hpp>

int main(int argc, char** argv) {
  if (argc < 2 || argc > 3) {
    std::fprintf(stderr, "usage: %s FILE [YYYY-MM-DD]\n", argv[0]);
    return 2;
  }
  gvins::rtcm::DecoderOptions options;
  options.streamName = argv[1];
  if (argc == 3) {
    gvins::CalendarTime c;
    if (std::sscanf(argv[2], "%d-%d-%d", &c.year, &c.month, &c.day) != 3) {
      std::fprintf(stderr, "%s: cannot read the date '%s' (expected YYYY-MM-DD)\n", argv[0], argv[2]);
      return 2;
    }
    options.referenceTime = gvins::GpsTime::fromCalendar(c);
  }
  std::ifstream in(argv[1], std::ios::binary);
  if (!in) {
    std::fprintf(stderr, "%s: cannot open\n", argv[1]);
    return 1;
  }
  try {
    gvins::rtcm::Decoder decoder(options);
    long epochs = 0, satellites = 0, firstSatellites = 0, ephemerides = 0;
    gvins::GpsTime first, last;
    const auto drain = [&] {
      while (auto item = decoder.poll()) {
        std::visit(
            [&](const auto& v) {
              using T = std::decay_t<decltype(v)>;
              if constexpr (std::is_same_v<T, gvins::ObsEpoch>) {
                if (epochs == 0) {
                  first = v.time;
                  firstSatellites = static_cast<long>(v.sats.size());
                }
                last = v.time;
                ++epochs;
                satellites += static_cast<long>(v.sats.size());
              } else if constexpr (std::is_same_v<T, gvins::KeplerEphemeris> ||
                                   std::is_same_v<T, gvins::GlonassEphemeris>) {
                ++ephemerides;
              }
            },
            *item);
      }
    };
    std::vector<char> chunk(1 << 16);
    while (in.read(chunk.data(), static_cast<std::streamsize>(chunk.size())) || in.gcount() > 0) {
      const auto n = static_cast<std::size_t>(in.gcount());
      decoder.feed({reinterpret_cast<const std::uint8_t*>(chunk.data()), n});
      drain();
    }
    decoder.finish();
    drain();

    const gvins::rtcm::DecoderStats& st = decoder.stats();
    for (const auto& [type, count] : st.messages) std::printf("message %d %lld\n", type, static_cast<long long>(count));
    std::printf("epochs %ld\n", epochs);
    if (epochs > 0) {
      std::printf("first_epoch %s satellites %ld\n", first.toString(1).c_str(), firstSatellites);
      std::printf("last_epoch %s\n", last.toString(1).c_str());
    }
    std::printf("satellite_epochs %ld\n", satellites);
    std::printf("ephemerides %ld\n", ephemerides);
    std::printf("crc_failures %lld malformed %lld\n", static_cast<long long>(st.framing.crcFailures),
                static_cast<long long>(st.malformed));
    if (const auto& pos = decoder.stationPosition())
      std::printf("station %d arp %.4f %.4f %.4f\n", pos->stationId, pos->arp.x(), pos->arp.y(), pos->arp.z());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}
