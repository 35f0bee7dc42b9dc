// Primary-signal choice with fallback across bands (signal_choice.hpp): the signals a u-blox X20P
// tracks (GPS L1 C/A, L2 CL, L5 Q; Galileo E1 C, E5a Q, E6 B; BeiDou B1C, B2a, B3I: the RXM-RAWX
// content of tests/data/ubx/gnss_1730.ubx), and the notices naming each fallback once.
#include <gtest/gtest.h>

#include <string>

#include "gvins/base/signal.hpp"
#include "gvins/gnss/signal_choice.hpp"
#include "gvins/gnss/spp_config.hpp"

using namespace gvins;

namespace {

SatObs satellite(System sys, int prn, std::initializer_list<const char*> codes) {
  SatObs so;
  so.sat = SatId{sys, prn};
  double pr = 2.1e7;
  for (const char* c : codes) {
    SignalObs s;
    s.code = *ObsCode::parse(c);
    s.setCode(pr += 1.0);
    so.signals.push_back(s);
  }
  return so;
}

}  // namespace

TEST(SignalChoice, BeiDouWithoutB1ITakesB3I) {
  // X20P BeiDou: B1C (1P), B2a (5P), B3I (6I); the SPP's BeiDou list is B1I, B2I, B3I.
  const SatObs so = satellite(System::BeiDou, 19, {"1P", "5P", "6I"});
  const std::string bands = SppConfig{}.bands[static_cast<std::size_t>(systemIndex(System::BeiDou))];
  ASSERT_EQ(bands.substr(0, 1), "2");
  const auto c = primaryCode(so, bands, 1, std::nullopt);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->signal->code.str(), "6I");
  EXPECT_DOUBLE_EQ(c->frequency, *carrierFrequency(System::BeiDou, '6'));
  // Without B3I the order goes on with B1C, then B2a.
  // (the signal pointers point into the SatObs: keep it alive)
  const SatObs b2 = satellite(System::BeiDou, 19, {"5P", "1P"}), b3 = satellite(System::BeiDou, 19, {"5P"});
  const auto c2 = primaryCode(b2, bands, 1, std::nullopt);
  ASSERT_TRUE(c2);
  EXPECT_EQ(c2->signal->code.str(), "1P");
  const auto c3 = primaryCode(b3, bands, 1, std::nullopt);
  ASSERT_TRUE(c3);
  EXPECT_EQ(c3->signal->code.str(), "5P");
}

TEST(SignalChoice, PreferredBandsFirst) {
  // GPS with L1 tracked keeps L1 whatever else is there; without it the next band of the list.
  const SatObs gps = satellite(System::Gps, 5, {"5Q", "2L", "1C"});
  EXPECT_EQ(primaryCode(gps, "125", 1, std::nullopt)->signal->code.str(), "1C");
  const SatObs noL1 = satellite(System::Gps, 5, {"5Q", "2L"});
  EXPECT_EQ(primaryCode(noL1, "125", 1, std::nullopt)->signal->code.str(), "2L");
  EXPECT_EQ(primaryCode(noL1, "152", 1, std::nullopt)->signal->code.str(), "5Q");
  // Galileo E6 only (not in the list "157"): the fallback order reaches it.
  const SatObs e6 = satellite(System::Galileo, 3, {"6B"});
  EXPECT_EQ(primaryCode(e6, "157", 1, std::nullopt)->signal->code.str(), "6B");
  // An unusable pseudorange (0 m) is not a signal.
  SatObs bad = satellite(System::Gps, 7, {"1C"});
  bad.signals[0].pseudorange = 0.0;
  EXPECT_FALSE(primaryCode(bad, "125", 3, std::nullopt));
}

TEST(SignalChoice, FallbackOrderAppendsMissingBands) {
  EXPECT_EQ(bandsWithFallback("276", System::BeiDou), "276158");
  EXPECT_EQ(bandsWithFallback("125", System::Gps), "125");
  EXPECT_EQ(bandsWithFallback("157", System::Galileo), "15786");
  for (int s = 0; s < kNumSystems; ++s) {
    const auto sys = static_cast<System>(s);
    for (char b : fallbackBands(sys)) EXPECT_TRUE(carrierFrequency(sys, b) || sys == System::Glonass) << b;
  }
}

TEST(SignalChoice, NoticesOncePerSystemAndSignal) {
  SignalFallbackNotices n;
  EXPECT_FALSE(n.record(System::Gps, '1', ObsCode('1', 'C')));  // the preferred band: nothing
  const auto m = n.record(System::BeiDou, '2', ObsCode('6', 'I'));
  ASSERT_TRUE(m);
  EXPECT_NE(m->find("BeiDou"), std::string::npos) << *m;
  EXPECT_NE(m->find("B1I"), std::string::npos) << *m;
  EXPECT_NE(m->find("B3I"), std::string::npos) << *m;
  EXPECT_NE(m->find("C6I"), std::string::npos) << *m;
  EXPECT_FALSE(n.record(System::BeiDou, '2', ObsCode('6', 'I')));  // once
  EXPECT_TRUE(n.record(System::BeiDou, '2', ObsCode('1', 'P')));   // another signal: its own notice
  EXPECT_EQ(n.messages().size(), 2u);
}
