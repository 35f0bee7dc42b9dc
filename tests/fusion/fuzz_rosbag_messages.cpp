// libFuzzer target for the ROS message deserialisers of the GVINS bag layouts: any input must
// decode or throw ParseError, and whatever decodes must convert to our types (or throw ParseError)
// and serialise back to the same bytes.
#include <cstdint>
#include <cstdlib>
#include <span>

#include "gvins/base/parse_error.hpp"
#include "gvins/fusion/rosbag_convert.hpp"
#include "gvins/fusion/rosbag_messages.hpp"

namespace {
template <class Msg>
void roundTrip(const Msg& m, std::span<const std::uint8_t> in) {
  const auto out = gvins::fusion::ros::serialize(m);
  if (out.size() != in.size() || !std::equal(out.begin(), out.end(), in.begin())) std::abort();
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  namespace r = gvins::fusion::ros;
  using namespace gvins::fusion;
  // First byte selects the message type; the rest is the message.
  const std::span<const std::uint8_t> b(data + 1, size - 1);
  try {
    switch (data[0] % 6) {
      case 0: {
        const auto m = r::deserializeGnssMeas(b, "fuzz");
        roundTrip(m, b);
        gvins::GlonassChannels ch;
        const gvins::ObsEpoch e = toObsEpoch(m, "fuzz", nullptr, &ch);
        (void)toGnssMeasMsg(e, ch);
        break;
      }
      case 1: {
        const auto m = r::deserializeGnssEphem(b, "fuzz");
        roundTrip(m, b);
        (void)toGnssEphemMsg(toKeplerEphemeris(m, "fuzz"));
        break;
      }
      case 2: {
        const auto m = r::deserializeGnssGloEphem(b, "fuzz");
        roundTrip(m, b);
        (void)toGnssGloEphemMsg(toGlonassEphemeris(m, "fuzz"));
        break;
      }
      case 3: {
        const auto m = r::deserializeImu(b, "fuzz");
        roundTrip(m, b);
        (void)toImuSample(m);
        break;
      }
      case 4: {
        const auto m = r::deserializeImage(b, "fuzz");
        roundTrip(m, b);
        (void)toMat(m, "fuzz");
        break;
      }
      case 5: {
        const auto m = r::deserializeCompressedImage(b, "fuzz");
        roundTrip(m, b);
        (void)toMat(m, "fuzz");
        break;
      }
    }
  } catch (const gvins::ParseError&) {
  }
  return 0;
}
