// Re-acquisition after the GNSS rows lost the state: when every epoch's rows were gated out for
// `after` seconds in a row (e.g. after an outage whose inertial drift exceeds what the filter's
// covariance admits: a MEMS IMU walking for 15 s without GNSS drifts by tens of metres), the
// fusion applies the rows without the chi-square gates for `window` seconds, so that the state
// comes back to the GNSS solution, and then gates again. Each re-acquisition gives one warning.
// Rows that keep failing only because of outliers do not trigger it in practice: an epoch with
// a good majority passes the gates, which resets the count.
#pragma once

#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "gvins/base/gnss_time.hpp"

namespace gvins::fusion {

class GnssGateRecovery {
 public:
  /// `after` <= 0: never (always gated).
  GnssGateRecovery(double after = 2.0, double window = 1.0) : after_(after), window_(window) {}

  /// Whether the rows of the epoch at t are gated.
  bool gated(const GpsTime& t) {
    if (!(after_ > 0.0)) return true;
    if (ungatedUntil_ && t <= *ungatedUntil_) return false;
    ungatedUntil_.reset();
    if (rejectedSince_ && t - *rejectedSince_ >= after_) {
      ungatedUntil_ = t + window_;
      char buf[160];
      std::snprintf(buf, sizeof buf,
                    "GNSS rows: every row gated out for %.1f s (the state drifted away, e.g. after an outage); "
                    "re-acquiring without the gates for %.1f s at %d %.3f",
                    t - *rejectedSince_, window_, t.week(), t.tow());
      warnings_.emplace_back(buf);
      rejectedSince_.reset();
      ++recoveries_;
      return false;
    }
    return true;
  }
  /// The outcome of the epoch's update (rows: how many were offered).
  void outcome(const GpsTime& t, bool applied, std::size_t rows) {
    if (applied) {
      rejectedSince_.reset();
    } else if (rows > 0 && !rejectedSince_) {
      rejectedSince_ = t;
    }
  }
  /// Forget the history (state reset).
  void reset() {
    rejectedSince_.reset();
    ungatedUntil_.reset();
  }
  const std::vector<std::string>& warnings() const { return warnings_; }
  int recoveries() const { return recoveries_; }

 private:
  double after_, window_;
  std::optional<GpsTime> rejectedSince_, ungatedUntil_;
  std::vector<std::string> warnings_;
  int recoveries_ = 0;
};

}  // namespace gvins::fusion
