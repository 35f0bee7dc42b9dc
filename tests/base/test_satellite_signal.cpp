#include <gtest/gtest.h>

#include <set>

#include "gvins/base/constants.hpp"
#include "gvins/base/observation.hpp"
#include "gvins/base/satellite.hpp"
#include "gvins/base/signal.hpp"

using namespace gvins;

TEST(Satellite, ParseAndPrint) {
  EXPECT_EQ(SatId::parse("G05")->str(), "G05");
  EXPECT_EQ(SatId::parse("R12")->system, System::Glonass);
  EXPECT_EQ(SatId::parse("C23")->prn, 23);
  EXPECT_EQ(SatId::parse("J02")->str(), "J02");
  EXPECT_EQ(SatId::parse("G 5")->str(), "G05");
  EXPECT_EQ(SatId::parse(" 5")->str(), "G05");  // RINEX 2 GPS
  EXPECT_EQ(SatId::parse("S27")->str(), "S27");
  EXPECT_EQ(SatId::parse("S127")->str(), "S27");
  EXPECT_EQ(SatId::parse("J193")->str(), "J01");
  EXPECT_FALSE(SatId::parse("G33"));
  EXPECT_FALSE(SatId::parse("G00"));
  EXPECT_FALSE(SatId::parse("X01"));
  EXPECT_FALSE(SatId::parse("S05"));
  EXPECT_FALSE(SatId::parse(""));
  EXPECT_FALSE(SatId::parse("G0A"));
}

TEST(Satellite, DenseIndexIsABijection) {
  std::set<int> seen;
  for (int s = 0; s < kNumSystems; ++s) {
    const System sys = static_cast<System>(s);
    for (int p = minPrn(sys); p <= maxPrn(sys); ++p) {
      const SatId id(sys, p);
      const int i = satIndex(id);
      EXPECT_GE(i, 0);
      EXPECT_LT(i, numSatIndices());
      EXPECT_TRUE(seen.insert(i).second);
      EXPECT_EQ(satFromIndex(i), id);
    }
  }
  EXPECT_EQ(static_cast<int>(seen.size()), numSatIndices());
}

TEST(Satellite, BeiDouOrbitClasses) {
  EXPECT_EQ(beidouOrbit(1), BeiDouOrbit::Geo);
  EXPECT_EQ(beidouOrbit(5), BeiDouOrbit::Geo);
  EXPECT_EQ(beidouOrbit(60), BeiDouOrbit::Geo);
  EXPECT_EQ(beidouOrbit(6), BeiDouOrbit::Igso);
  EXPECT_EQ(beidouOrbit(38), BeiDouOrbit::Igso);
  EXPECT_EQ(beidouOrbit(11), BeiDouOrbit::Meo);
  EXPECT_EQ(beidouOrbit(23), BeiDouOrbit::Meo);
  EXPECT_TRUE(isBeiDouGeo(SatId(System::BeiDou, 3)));
  EXPECT_FALSE(isBeiDouGeo(SatId(System::Gps, 3)));
}

TEST(Signal, CarrierFrequenciesFromIcds) {
  EXPECT_DOUBLE_EQ(*carrierFrequency(System::Gps, '1'), 1575.42e6);
  EXPECT_DOUBLE_EQ(*carrierFrequency(System::Gps, '2'), 1227.60e6);
  EXPECT_DOUBLE_EQ(*carrierFrequency(System::Gps, '5'), 1176.45e6);
  EXPECT_DOUBLE_EQ(*carrierFrequency(System::Galileo, '7'), 1207.14e6);
  EXPECT_DOUBLE_EQ(*carrierFrequency(System::Galileo, '8'), 1191.795e6);
  EXPECT_DOUBLE_EQ(*carrierFrequency(System::BeiDou, '2'), 1561.098e6);
  EXPECT_DOUBLE_EQ(*carrierFrequency(System::BeiDou, '6'), 1268.52e6);
  EXPECT_DOUBLE_EQ(*carrierFrequency(System::Qzss, '6'), 1278.75e6);
  EXPECT_DOUBLE_EQ(*carrierFrequency(System::Glonass, '1', -7), 1598.0625e6);
  EXPECT_DOUBLE_EQ(*carrierFrequency(System::Glonass, '2', 6), 1248.625e6);
  EXPECT_DOUBLE_EQ(*carrierFrequency(System::Glonass, '3'), 1202.025e6);
  EXPECT_FALSE(carrierFrequency(System::Glonass, '1'));      // channel needed
  EXPECT_FALSE(carrierFrequency(System::Glonass, '1', 7));   // out of range
  EXPECT_FALSE(carrierFrequency(System::Gps, '7'));
  EXPECT_NEAR(*carrierWavelength(System::Gps, '1'), 0.190293672798, 1e-12);
}

TEST(Signal, CodesAndPriorities) {
  EXPECT_EQ(ObsCode::parse("1C")->str(), "1C");
  EXPECT_FALSE(ObsCode::parse("C1"));
  EXPECT_FALSE(ObsCode::parse("1"));
  EXPECT_EQ(normalizeObsCode(System::BeiDou, ObsCode('1', 'I'), 3.02), ObsCode('2', 'I'));
  EXPECT_EQ(normalizeObsCode(System::BeiDou, ObsCode('1', 'P'), 3.04), ObsCode('1', 'P'));
  EXPECT_EQ(normalizeObsCode(System::BeiDou, ObsCode('1', 'I'), 3.04), ObsCode('1', 'I'));
  SatObs o{SatId(System::Gps, 5), {}};
  SignalObs w;
  w.code = ObsCode('1', 'W');
  w.setCode(2.0e7);
  SignalObs c;
  c.code = ObsCode('1', 'C');
  c.setCode(2.0e7 + 1);
  o.signals = {w, c};
  ASSERT_NE(o.bestOnBand('1'), nullptr);
  EXPECT_EQ(o.bestOnBand('1')->code, ObsCode('1', 'C'));
  EXPECT_EQ(o.bestOnBand('1', SignalObs::kPhase), nullptr);
  EXPECT_EQ(o.bestOnBand('2'), nullptr);
}

TEST(Observation, GlonassChannelTable) {
  GlonassChannels a, b;
  EXPECT_TRUE(a.empty());
  a.set(1, 1);
  b.set(1, -4);
  b.set(2, -4);
  b.set(30, 0);  // ignored
  a.mergeMissing(b);
  EXPECT_EQ(a.get(1), 1);
  EXPECT_EQ(a.get(2), -4);
  EXPECT_FALSE(a.get(3));
  EXPECT_FALSE(a.get(28));
}
