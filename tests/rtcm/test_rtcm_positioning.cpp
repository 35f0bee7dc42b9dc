// Streaming positioning from RTCM: the GMSD log's ephemerides decoded into an EphemerisStore (as
// RINEX records would be; a rover has them before it starts), then its MSM7 observations decoded
// as they arrive in socket-sized pieces, with SPP and Doppler velocity each epoch, against the IGS
// position of GMSD and a static receiver.
#include <gtest/gtest.h>

#include "gvins/base/local_frame.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/gnss/spp.hpp"
#include "gvins/rtcm/decoder.hpp"
#include "independent_frame_scan.hpp"

namespace gvins::rtcm {
namespace {

TEST(Streaming, GmsdSppAndDopplerVelocityFromMsm7) {
  // GMSD (Tanegashima), IGS SINEX, epoch 2020 (../shared/data/README.md); the site moves a few
  // cm per year, far below SPP errors.
  const Eigen::Vector3d truth(-3607665.545, 4147867.881, 3223716.919);
  const auto bytes = testing::readBytes(testing::dataDir() / "rtcm/rtklib_GMSD7_20121014.rtcm3");
  DecoderOptions opt;
  opt.referenceTime = GpsTime::fromCalendar({2012, 10, 13, 12, 0, 0.0});
  EphemerisStore store;
  {
    Decoder eph(opt);
    eph.feed(bytes);
    eph.finish();
    int records = 0;
    while (auto item = eph.poll()) {
      if (const auto* k = std::get_if<KeplerEphemeris>(&*item)) store.add(*k), ++records;
      if (const auto* g = std::get_if<GlonassEphemeris>(&*item)) store.add(*g), ++records;
    }
    ASSERT_EQ(records, 31);
  }
  // The records carry their reception time as transmission time; let the store use them from the
  // start, as a rover's own broadcast records would be.
  SppConfig cfg;
  cfg.ephemeris.futureTolerance = 4 * 3600.0;
  Decoder dec(opt);
  SppSolver spp(store, cfg);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double speed2 = 0.0;
  int solved = 0, withVelocity = 0, epochs = 0;
  auto drain = [&] {
    while (auto item = dec.poll()) {
      if (const auto* e = std::get_if<ObsEpoch>(&*item)) {
        ++epochs;
        spp.setGlonassChannels(dec.glonassChannels());
        const SppSolution s = spp.solve(*e);
        if (!s.valid()) continue;
        ++solved;
        sum += s.position;
        if (s.velocity.valid) {
          ++withVelocity;
          speed2 += s.velocity.velocity.squaredNorm();
        }
      }
    }
  };
  for (std::size_t i = 0; i < bytes.size(); i += 512) {  // as from a socket
    dec.feed({bytes.data() + i, std::min<std::size_t>(512, bytes.size() - i)});
    drain();
  }
  dec.finish();
  drain();
  ASSERT_EQ(epochs, 257);
  ASSERT_GT(solved, 200);
  const Eigen::Vector3d mean = sum / solved;
  const double rmsSpeed = std::sqrt(speed2 / std::max(withVelocity, 1));
  std::cerr << "GMSD streaming SPP: " << solved << "/" << epochs << " epochs, mean 3D error " << (mean - truth).norm()
            << " m; Doppler velocity of the static antenna: RMS " << rmsSpeed << " m/s over " << withVelocity
            << " epochs\n";
  // For scale: RTKLIB 2.4.3 (rnx2rtkp -p 0 -m 15 -e) on our RINEX conversion of the log: 6.8 m.
  EXPECT_LT((mean - truth).norm(), 8.0);
  EXPECT_GT(withVelocity, 200);
  EXPECT_LT(rmsSpeed, 0.1);
}

}  // namespace
}  // namespace gvins::rtcm
