// Checks that decoded SSR satellites equal the ones sent, to half an LSB of each field's resolution
// (RTCM 10403.3 DF365-DF370, DF376-DF378, DF383, DF389, DF390). Shared by the SSR message and
// SSR file tests.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "gvins/ephemeris/ssr_message.hpp"

namespace gvins::test {

inline void expectQuantized(double got, double want, double lsb, const char* what) {
  EXPECT_LE(std::abs(got - want), 0.5 * lsb * (1 + 1e-9) + 1e-12) << what << ": got " << got << ", sent " << want;
}

inline void expectSameSatellites(const std::vector<SsrSatellite>& got, const std::vector<SsrSatellite>& sent) {
  ASSERT_EQ(got.size(), sent.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    const SsrSatellite& a = got[i];
    const SsrSatellite& b = sent[i];
    SCOPED_TRACE(b.sat.str());
    EXPECT_EQ(a.sat, b.sat);
    ASSERT_EQ(a.orbit.has_value(), b.orbit.has_value());
    ASSERT_EQ(a.clock.has_value(), b.clock.has_value());
    ASSERT_EQ(a.uraIndex.has_value(), b.uraIndex.has_value());
    ASSERT_EQ(a.highRateClock.has_value(), b.highRateClock.has_value());
    if (b.orbit) {
      EXPECT_EQ(a.orbit->issueOfData, b.orbit->issueOfData);
      EXPECT_EQ(a.orbit->iodCrc, b.orbit->iodCrc);
      expectQuantized(a.orbit->rac.x(), b.orbit->rac.x(), 1e-4, "DF365");
      expectQuantized(a.orbit->rac.y(), b.orbit->rac.y(), 4e-4, "DF366");
      expectQuantized(a.orbit->rac.z(), b.orbit->rac.z(), 4e-4, "DF367");
      expectQuantized(a.orbit->racRate.x(), b.orbit->racRate.x(), 1e-6, "DF368");
      expectQuantized(a.orbit->racRate.y(), b.orbit->racRate.y(), 4e-6, "DF369");
      expectQuantized(a.orbit->racRate.z(), b.orbit->racRate.z(), 4e-6, "DF370");
    }
    if (b.clock) {
      expectQuantized(a.clock->c0, b.clock->c0, 1e-4, "DF376");
      expectQuantized(a.clock->c1, b.clock->c1, 1e-6, "DF377");
      expectQuantized(a.clock->c2, b.clock->c2, 2e-8, "DF378");
    }
    if (b.uraIndex) {
      EXPECT_EQ(*a.uraIndex, *b.uraIndex);
    }
    if (b.highRateClock) expectQuantized(*a.highRateClock, *b.highRateClock, 1e-4, "DF390");
    ASSERT_EQ(a.codeBiases.size(), b.codeBiases.size());
    for (std::size_t k = 0; k < a.codeBiases.size(); ++k) {
      EXPECT_EQ(a.codeBiases[k].first, b.codeBiases[k].first);
      expectQuantized(a.codeBiases[k].second, b.codeBiases[k].second, 0.01, "DF383");
    }
  }
}

}  // namespace gvins::test
