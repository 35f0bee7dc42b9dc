// The base receiver's clock in the dpsr rows (vio+dopp+dpsr, vio+dopp+ddcp): the rows are on the
// rover clock, r = sdCodeResidual + ĉdt_b − c·dt_r, so c·dt_b of each clock system is taken from
// the base's code residuals OMC_b = c·dt_b + I_b + T_b − T_model + multipath + ... of the single
// differences. Their plain mean also holds the mean of the per-satellite terms, the unmodelled
// base ionosphere above all (metres, largest at low elevation), so it jumps whenever a satellite
// joins or leaves the set (crosses the elevation mask, rises, sets): e.g. a Galileo satellite at
// 15° whose E1/E5a base residuals are 12/20 m above the others moves the mean of ten rows by
// 2.7 m, a jump of every row of the system that the rover clock and inter-system bias (random
// walks of 0.1 and 0.001 m/√s) cannot follow, so the whole system is gated out from then on.
// Here the estimate is continued from the previous epoch with the mean change of the residuals of
// the signals common to both epochs: it follows c·dt_b and the slow drift of the terms, and a
// change of the set no longer moves it. The offset it keeps from c·dt_b is constant and goes into
// the rover's clock states like any receiver bias.
#pragma once

#include <cmath>
#include <cstdint>
#include <map>
#include <vector>

namespace gvins::fusion {

class GnssBaseClock {
 public:
  /// One base code residual of an epoch: the clock system's index, the signal (any key unique per
  /// satellite and code) and OMC_b in m.
  struct Residual {
    int system = 0;
    std::int64_t signal = 0;
    double omc = 0.0;
  };

  /// The base clock per system (index < systems) at this epoch, m; NaN for a system without
  /// residuals. Continued over the signals common with the system's previous epoch, else (first
  /// epoch, no common signal) the mean of the epoch's residuals.
  std::vector<double> update(const std::vector<Residual>& residuals, int systems) {
    if (static_cast<int>(last_.size()) < systems) last_.resize(static_cast<std::size_t>(systems));
    std::vector<double> out(static_cast<std::size_t>(systems), std::nan(""));
    for (int s = 0; s < systems; ++s) {
      Epoch now;
      double sum = 0.0, change = 0.0;
      int common = 0;
      Epoch& last = last_[static_cast<std::size_t>(s)];
      for (const Residual& r : residuals) {
        if (r.system != s) continue;
        now.omc[r.signal] = r.omc;
        sum += r.omc;
        const auto it = last.omc.find(r.signal);
        if (it == last.omc.end()) continue;
        change += r.omc - it->second;
        ++common;
      }
      if (now.omc.empty()) continue;  // keep the last epoch: the system may come back
      now.clock = common > 0 && std::isfinite(last.clock) ? last.clock + change / common
                                                          : sum / static_cast<double>(now.omc.size());
      out[static_cast<std::size_t>(s)] = now.clock;
      last = std::move(now);
    }
    return out;
  }

  /// Forget the history (the clock states start again).
  void reset() { last_.clear(); }

 private:
  struct Epoch {
    std::map<std::int64_t, double> omc;
    double clock = std::nan("");
  };
  std::vector<Epoch> last_;
};

}  // namespace gvins::fusion
