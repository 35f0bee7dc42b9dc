// Accuracy of position (and velocity) solutions against a known truth, in the local
// east/north/up frame of the truth: mean, RMS, standard deviation per axis, horizontal and
// vertical RMS, 95th percentiles and maxima. Memory does not grow with the number of epochs
// (percentiles come from fine logarithmic histograms, relative resolution 0.1 %).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace gvins {

/// Streaming percentile estimate of a non-negative quantity from a logarithmic histogram
/// (1e-6 .. 1e7, 0.1 % bins).
class QuantileHistogram {
 public:
  QuantileHistogram();
  void add(double value);
  /// Value below which a fraction q (0..1) of the samples lie (bin upper edge; exact to 0.1 %).
  double quantile(double q) const;
  std::int64_t count() const { return count_; }

 private:
  std::vector<std::uint32_t> bins_;
  std::int64_t count_ = 0;
};

struct AxisStatistics {
  double mean = 0.0;
  double rms = 0.0;
  double stddev = 0.0;
};

struct AccuracySummary {
  std::int64_t count = 0;
  std::array<AxisStatistics, 3> enu;  ///< east, north, up
  double horizontalRms = 0.0;         ///< sqrt(mean(e^2 + n^2))
  double verticalRms = 0.0;           ///< sqrt(mean(u^2))
  double rms3d = 0.0;
  double horizontal95 = 0.0;          ///< 95th percentile of sqrt(e^2 + n^2)
  double vertical95 = 0.0;            ///< 95th percentile of |u|
  double horizontalMax = 0.0;
  double verticalMax = 0.0;
};

class AccuracyStatistics {
 public:
  /// Truth position (ECEF) for position errors; truth velocity (ECEF, default zero) for velocity.
  explicit AccuracyStatistics(const Eigen::Vector3d& truthEcef,
                              const Eigen::Vector3d& truthVelocityEcef = Eigen::Vector3d::Zero());
  void addPosition(const Eigen::Vector3d& ecef);
  void addVelocity(const Eigen::Vector3d& velocityEcef);

  AccuracySummary position() const;
  AccuracySummary velocity() const;
  /// ENU error of a position with respect to the truth.
  Eigen::Vector3d enuError(const Eigen::Vector3d& ecef) const;

  /// Text table (position, and velocity when any was added) for terminal summaries.
  std::string table() const;

 private:
  struct Accumulator {
    std::int64_t n = 0;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    Eigen::Vector3d sumSq = Eigen::Vector3d::Zero();
    double maxH = 0.0, maxV = 0.0;
    QuantileHistogram h, v;
    void add(const Eigen::Vector3d& enu);
    AccuracySummary summary() const;
  };
  Eigen::Vector3d truth_;
  Eigen::Vector3d truthVel_;
  Eigen::Matrix3d rot_;
  Accumulator pos_, vel_;
};

/// Formats a summary as rows "east north up horizontal vertical" (helper of table()).
std::string formatAccuracyTable(const AccuracySummary& s, const std::string& title, const std::string& unit);

}  // namespace gvins
