// The simulated atmosphere: slant tropospheric and ionospheric delays that the usual models
// (Saastamoinen + Niell, broadcast Klobuchar) remove only partly.
//
//   troposphere  T = ZHD (1 + e_h) m_h + [ZWD (1 + e_w) + dZWD(p, t) exp(-(h - h0)/2000 m)] m_w
//     ZHD, ZWD, m_h, m_w: Saastamoinen zenith delays of a standard atmosphere and Niell mapping
//     (gnss/troposphere.hpp); e_h, e_w drawn once per run; dZWD a horizontal random field sampled
//     where the slant path crosses a layer `layerHeight` above the receiver.
//   ionosphere   I_L1 = K (1 + e_i) + M(el) * 40.3e16 / f_L1^2 * dVTEC(ipp, t)
//     K: GPS Klobuchar slant delay on L1 (gnss/klobuchar.hpp) with the navigation file's
//     parameters; M the single-layer obliquity factor at shell height H; dVTEC (TECU) random
//     fields at the ionospheric pierce point; I on frequency f is I_L1 (f_L1/f)^2 (first order,
//     e.g. Hofmann-Wellenhof et al., "GNSS", 2008, 5.3.2), a delay of the code and an advance
//     of the carrier phase.
// Base and rover sample the same fields at their own pierce points, so their errors are
// correlated and differ more the farther apart they are.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "gvins/base/geodetic.hpp"
#include "gvins/base/gnss_time.hpp"
#include "gvins/base/local_frame.hpp"
#include "gvins/ephemeris/ionosphere_parameters.hpp"
#include "gvins/sim/gnss_random_field.hpp"
#include "gvins/sim/gnss_sim_config.hpp"

namespace gvins::sim {

/// Slant delays of one receiver-satellite path, m.
struct GnssAtmosphereDelays {
  double troposphere = 0.0;       ///< true slant delay
  double troposphereModel = 0.0;  ///< Saastamoinen (standard atmosphere) + Niell
  double ionosphereL1 = 0.0;      ///< true slant group delay at 1575.42 MHz
  double ionosphereModelL1 = 0.0; ///< GPS Klobuchar
};

/// GPS L1 frequency, the reference of the ionospheric delays (IS-GPS-200N 3.3.1.1).
inline constexpr double kGnssSimL1Frequency = 1575.42e6;
/// Ionospheric group delay per TECU at frequency f: 40.3e16 / f^2 m (first-order term).
double ionosphereMetersPerTecu(double frequency);

class GnssAtmosphere {
 public:
  /// `klobuchar`: the GPS broadcast parameters of the navigation file (if the file has none, the
  /// ones broadcast on 2024-06-24 in tests/data/gnss/nagoya_static_2024/base.nav are used).
  GnssAtmosphere(const GnssSimConfig& config, const std::optional<KlobucharParameters>& klobuchar,
                 const Geodetic& origin, const GpsTime& start, std::uint64_t seed);

  GnssAtmosphereDelays delays(const Geodetic& receiver, const Eigen::Vector3d& receiverEcef, const AzEl& azel,
                              const GpsTime& t) const;

  double hydrostaticScale() const { return 1.0 + eh_; }
  double wetScale() const { return 1.0 + ew_; }
  double ionosphereScale() const { return 1.0 + ei_; }
  const KlobucharParameters& klobuchar() const { return klobuchar_; }

 private:
  GnssTroposphereConfig tropo_;
  GnssIonosphereConfig iono_;
  KlobucharParameters klobuchar_;
  Geodetic origin_;
  Eigen::Vector3d originEcef_;
  Eigen::Matrix3d enuFromEcef_;
  GpsTime start_;
  double eh_ = 0.0, ew_ = 0.0, ei_ = 0.0;
  std::vector<GnssRandomField> tropoFields_;
  std::vector<GnssRandomField> ionoFields_;
};

}  // namespace gvins::sim
