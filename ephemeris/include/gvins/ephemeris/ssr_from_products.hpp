// SSR corrections made from precise products, as a real-time correction service computes them
// (used by gvins-sim for its SSR stream and by `gvins-rtcm ssr`): every `interval` seconds, one combined orbit-and-clock message per system (RTCM 1060 GPS,
// 1066 GLONASS, 1243 Galileo, 1249 QZSS, 1261 BeiDou) whose corrections turn the broadcast record a
// receiver holds at that epoch (transmission time not after it) into the precise products' state
// (EphemerisStore::preciseState, antenna offsets applied) at the correction's
// reference time epoch + interval/2, with the rates of the differences. The corrections therefore
// carry the products' errors plus what a real-time user adds: latency (a correction is used until
// the next one, up to `interval` later, extrapolated by its rates) and the RTCM quantisation
// (0.1 mm). Code biases are not sent: the broadcast group delays apply to SSR-corrected clocks as
// to broadcast ones, which is right when the products' clocks are in the broadcast clock datum
// (gvins-sim's are; IGS clocks with their OSBs would need the OSB-TGD differences as SSR code
// biases: not done).
#pragma once

#include <vector>

#include "gvins/base/gnss_time.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/ephemeris/ssr_message.hpp"

namespace gvins {

struct SsrServiceConfig {
  double interval = 5.0;  ///< s; also the SSR update interval (DF391 value; 0 = no SSR stream)
  int providerId = 1;     ///< DF414
  int solutionId = 0;     ///< DF415
  int iodSsr = 1;         ///< DF413
};

/// Messages for the epochs k·interval in [start, end]. `broadcast` holds the broadcast records,
/// `products` the precise states (EphemerisStore::preciseState, with the products' antennas).
/// Satellites with no record or no precise state at an epoch are left out of it.
std::vector<SsrMessage> ssrFromProducts(const EphemerisStore& broadcast, const EphemerisStore& products,
                                        const GpsTime& start, const GpsTime& end, const SsrServiceConfig& config);

}  // namespace gvins
