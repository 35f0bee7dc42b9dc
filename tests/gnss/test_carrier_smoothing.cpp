// Carrier smoothing (CarrierSmoother) on synthetic dual-frequency observations with known range,
// ionosphere, noise and slips: the noise reduction of a Hatch filter, the single-frequency
// ionospheric lag against the divergence-free ionosphere-free combination, and every arc restart.
// The real-data check (SPP on two static recordings) is in test_spp.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "gvins/base/constants.hpp"
#include "gvins/base/signal.hpp"
#include "gvins/gnss/carrier_smoothing.hpp"
#include "gvins/gnss/ionosphere_free.hpp"

using namespace gvins;

namespace {

const SatId kSat{System::Gps, 5};
const ObsCode kL1{'1', 'C'}, kL5{'5', 'Q'};
const double kF1 = *carrierFrequency(System::Gps, '1');
const double kF5 = *carrierFrequency(System::Gps, '5');
const double kLambda1 = constants::kSpeedOfLight / kF1;
const double kLambda5 = constants::kSpeedOfLight / kF5;

/// One satellite, L1 C/A and L5 Q at 1 Hz: range 2.2e7 m + 300 m/s t (plus a slow curvature), L1
/// ionosphere 4 m + `ionoRate` t (L5 scaled by (f1/f5)²), code noise `sigma` white, phases with
/// arbitrary ambiguities and no noise.
struct Scenario {
  double sigma = 1.0;
  double ionoRate = 0.0;  ///< m/s on L1
  std::mt19937 rng{11};
  double range(double t) const { return 2.2e7 + 300.0 * t + 0.02 * t * t; }
  double iono1(double t) const { return 4.0 + ionoRate * t; }
  double iono5(double t) const { return iono1(t) * (kF1 / kF5) * (kF1 / kF5); }
  ObsEpoch epoch(double t) {
    std::normal_distribution<double> n(0.0, sigma);
    ObsEpoch e;
    e.time = GpsTime::fromWeekTow(2320, 100000.0 + t);
    SatObs& so = e.add(kSat);
    SignalObs s1, s5;
    s1.code = kL1;
    s1.setCode(range(t) + iono1(t) + n(rng));
    s1.setPhase((range(t) - iono1(t)) / kLambda1 + 1234567.0);
    s5.code = kL5;
    s5.setCode(range(t) + iono5(t) + n(rng));
    s5.setPhase((range(t) - iono5(t)) / kLambda5 - 7654321.0);
    so.signals = {s1, s5};
    return e;
  }
};

struct Stats {
  double mean = 0.0, sd = 0.0;
};
Stats stats(const std::vector<double>& v) {
  Stats s;
  for (double x : v) s.mean += x;
  s.mean /= static_cast<double>(v.size());
  for (double x : v) s.sd += (x - s.mean) * (x - s.mean);
  s.sd = std::sqrt(s.sd / static_cast<double>(v.size() - 1));
  return s;
}

}  // namespace

// Steady state of w = Δt/T: white noise σ becomes σ sqrt(w/(2 − w)) (0.0709 σ for T = 100 s at 1
// Hz); during the first T seconds the running mean gives σ/sqrt(n). noiseFactor() says the same.
TEST(CarrierSmoothing, WhiteNoiseDropsAsTheHatchFilterPredicts) {
  Scenario sc;
  CarrierSmoother sm;  // 100 s
  std::vector<double> steady, at25;
  for (int k = 0; k < 3000; ++k) {
    const double t = k;
    ObsEpoch e = sc.epoch(t);
    sm.apply(e);
    const double err = e.sats[0].signals[0].pseudorange - (sc.range(t) + sc.iono1(t));
    if (k >= 400) steady.push_back(err);
    if (k == 24) {
      EXPECT_NEAR(sm.noiseFactor(kSat), 1.0 / 5.0, 1e-12);  // 25 samples
    }
  }
  const double predicted = std::sqrt(0.01 / 1.99);
  EXPECT_NEAR(sm.noiseFactor(kSat), predicted, 1e-12);
  EXPECT_EQ(sm.samples(kSat), 3000);
  EXPECT_NEAR(sm.arcLength(kSat), 2999.0, 1e-9);
  const Stats s = stats(steady);
  // 2600 samples correlated over ~100 s: the sample sd is good to ~15 %.
  EXPECT_NEAR(s.sd, predicted, 0.2 * predicted);
  EXPECT_NEAR(s.mean, 0.0, 0.05);
  std::printf("smoothed code error sd %.4f m (predicted %.4f), mean %.4f m\n", s.sd, predicted, s.mean);
  EXPECT_EQ(sm.counts().smoothed, 2999);
  EXPECT_EQ(sm.counts().raw, 1);
}

// A changing ionosphere: each smoothed band lags by about 2 T dI/dt (code and carrier diverge by
// twice the ionospheric change), but both bands share their arc, so the ionosphere-free
// combination of the smoothed codes has no lag.
TEST(CarrierSmoothing, IonosphereFreeCombinationOfSmoothedCodesHasNoDivergence) {
  Scenario sc;
  sc.sigma = 0.3;
  sc.ionoRate = 0.004;  // m/s on L1: 0.4 m per window
  CarrierSmoother sm;
  const IonosphereFreeCoefficients c = ionosphereFreeCoefficients(kF1, kF5);
  std::vector<double> l1, ifc;
  for (int k = 0; k < 1500; ++k) {
    const double t = k;
    ObsEpoch e = sc.epoch(t);
    sm.apply(e);
    const double p1 = e.sats[0].signals[0].pseudorange, p5 = e.sats[0].signals[1].pseudorange;
    if (k < 600) continue;
    l1.push_back(p1 - (sc.range(t) + sc.iono1(t)));
    ifc.push_back(c.a1 * p1 + c.a2 * p5 - sc.range(t));
  }
  // Steady-state lag of an exponential filter on a ramp 2 İ t: 2 İ (T − Δt) = 0.792 m, negative.
  EXPECT_NEAR(stats(l1).mean, -2.0 * 0.004 * 99.0, 0.03);
  EXPECT_NEAR(stats(ifc).mean, 0.0, 0.06);  // ~9 independent windows of sd 0.05
  std::printf("L1 lag %.4f m, ionosphere-free mean %.4f m sd %.4f m\n", stats(l1).mean, stats(ifc).mean, stats(ifc).sd);
  // The combination's noise: 2.59 σ raw, times the smoothing factor.
  EXPECT_LT(stats(ifc).sd, 2.59 * 0.3 * 0.0709 * 1.3);
}

// Arc restarts: loss of lock, an undetected 100-cycle slip on L5 (geometry-free test), a code jump
// of 30 m with a continuous phase (code-carrier test), a new signal, a gap, and a band without
// phase. After a restart the code is the raw code.
TEST(CarrierSmoothing, ArcsRestartOnSlipsJumpsGapsAndSignalChanges) {
  Scenario sc;
  sc.sigma = 0.5;
  CarrierSmoother sm;
  auto run = [&](double t0, int n) {
    for (int k = 0; k < n; ++k) {
      ObsEpoch e = sc.epoch(t0 + k);
      sm.apply(e);
    }
  };
  run(0, 50);
  ASSERT_EQ(sm.samples(kSat), 50);

  ObsEpoch e = sc.epoch(50);
  e.sats[0].signals[1].lli = 1;
  const double raw = e.sats[0].signals[0].pseudorange;
  sm.apply(e);
  EXPECT_EQ(sm.samples(kSat), 1);
  EXPECT_EQ(e.sats[0].signals[0].pseudorange, raw);  // both bands restart together
  EXPECT_EQ(sm.counts().slipRestarts, 1);
  run(51, 20);
  EXPECT_EQ(sm.samples(kSat), 21);

  e = sc.epoch(71);
  e.sats[0].signals[1].carrierPhase += 100.0;  // no LLI
  sm.apply(e);
  EXPECT_EQ(sm.samples(kSat), 1);
  EXPECT_EQ(sm.counts().slipRestarts, 2);
  run(72, 10);

  e = sc.epoch(82);
  e.sats[0].signals[0].pseudorange += 30.0;
  sm.apply(e);
  EXPECT_EQ(sm.samples(kSat), 1);
  EXPECT_EQ(sm.counts().jumpRestarts, 1);
  run(83, 10);

  // A third signal (L2 code carried by... nothing: no L2 phase) → the satellite stays raw.
  e = sc.epoch(93);
  SignalObs l2;
  l2.code = ObsCode{'2', 'W'};
  l2.setCode(sc.range(93) + 6.6);
  e.sats[0].signals.push_back(l2);
  const double rawL1 = e.sats[0].signals[0].pseudorange;
  sm.apply(e);
  EXPECT_EQ(sm.samples(kSat), 0);
  EXPECT_EQ(e.sats[0].signals[0].pseudorange, rawL1);
  EXPECT_DOUBLE_EQ(sm.noiseFactor(kSat), 1.0);

  // A code without its own phase on a band that has one (C1W with L1C) is smoothed with it.
  run(94, 5);
  for (int k = 0; k < 5; ++k) {
    e = sc.epoch(99 + k);
    SignalObs w;
    w.code = ObsCode{'1', 'W'};
    w.setCode(sc.range(99 + k) + sc.iono1(99 + k) + 0.3);
    e.sats[0].signals.push_back(w);
    sm.apply(e);
  }
  EXPECT_EQ(sm.samples(kSat), 5);  // restarted once by the new signal, then continued
  EXPECT_GE(sm.counts().signalRestarts, 1);

  // A gap longer than the slip detector's maxGap (60 s): a new arc.
  run(200, 3);
  EXPECT_EQ(sm.samples(kSat), 3);
  // Satellites missing from an epoch report no samples.
  ObsEpoch empty;
  empty.time = GpsTime::fromWeekTow(2320, 100000.0 + 203);
  sm.apply(empty);
  EXPECT_EQ(sm.samples(kSat), 0);

  sm.reset();
  run(300, 2);
  EXPECT_EQ(sm.samples(kSat), 2);
}

// Window 0: codes pass through unchanged.
TEST(CarrierSmoothing, ZeroWindowKeepsRawCodes) {
  Scenario sc;
  CarrierSmoothingOptions o;
  o.window = 0.0;
  CarrierSmoother sm(o);
  for (int k = 0; k < 10; ++k) {
    ObsEpoch e = sc.epoch(k);
    const ObsEpoch before = e;
    sm.apply(e);
    EXPECT_EQ(e.sats[0].signals[0].pseudorange, before.sats[0].signals[0].pseudorange);
    EXPECT_EQ(e.sats[0].signals[1].pseudorange, before.sats[0].signals[1].pseudorange);
  }
}
