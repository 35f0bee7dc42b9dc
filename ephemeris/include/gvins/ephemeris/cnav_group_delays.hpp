// Group delay and inter-signal corrections of GPS and QZSS CNAV message type 30 (IS-GPS-200N
// appendix III 30.3.3.3.1.1, IS-GPS-705J 20.3.3.3.1.2, figure 30-3 / 20-3; QZSS: IS-QZSS-PNT-005,
// the same message), with the message's clock parameters.
#pragma once

#include <optional>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/satellite.hpp"

namespace gvins {

struct CnavGroupDelays {
  SatId sat;
  /// GPST at the end of the message (its TOW count: the start of the next message, IS-GPS-200N
  /// 30.3.3.1): the time from which the values are known.
  GpsTime time;

  /// T_GD and the inter-signal corrections ISC_L1C/A = t_L1P(Y) − t_L1C/A, ISC_L2C =
  /// t_L1P(Y) − t_L2C, ISC_L5I5 = t_L1P(Y) − t_L5I5, ISC_L5Q5 = t_L1P(Y) − t_L5Q5, s; std::nullopt
  /// where the message says "not available" (the 13-bit value 1000000000000b).
  std::optional<double> tgd, iscL1ca, iscL2c, iscL5i5, iscL5q5;

  /// Clock of the message (types 30-37 carry it): toc and af0..af2 (s, s/s, s/s^2). The clock
  /// refers to the L1/L2 P(Y) ionosphere-free pair like the LNAV clock (30.3.3.2.3).
  GpsTime toc;
  double af0 = 0.0, af1 = 0.0, af2 = 0.0;

  /// The same corrections (clock apart): a repeated message.
  bool sameCorrections(const CnavGroupDelays& o) const {
    return sat == o.sat && tgd == o.tgd && iscL1ca == o.iscL1ca && iscL2c == o.iscL2c && iscL5i5 == o.iscL5i5 &&
           iscL5q5 == o.iscL5q5;
  }
};

/// A CNAV message type 30 older than this (s) is not used: the corrections change rarely, but an
/// old message of a satellite that stopped sending CNAV is no evidence for today.
inline constexpr double kCnavGroupDelayMaxAge = 86400.0;

}  // namespace gvins
