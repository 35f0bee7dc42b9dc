// The replay summary: the table printed at the end of gvins-replay and metrics.csv.
#include <cstdio>
#include <ostream>
#include <string>

#include "gvins/fusion/replay_pipeline.hpp"

namespace gvins::fusion {

void ReplaySummary::writeMetrics(std::ostream& os) const {
  auto kv = [&](const char* k, double v) {
    char b[96];
    std::snprintf(b, sizeof b, "%s,%.6g\n", k, v);
    os << b;
  };
  os << "# gvins-replay figures: key,value (NaN: not evaluated); docs/replay.md\n";
  kv("frames", static_cast<double>(framesProcessed));
  kv("frames_initialized", static_cast<double>(framesInitialized));
  kv("vio_resets", static_cast<double>(estimatorResets));
  kv("dataset_s", datasetSeconds);
  kv("wall_s", wallSeconds);
  kv("cpu_s", cpuSeconds);
  kv("real_time_factor", realTimeFactor());
  kv("frontend_ms_mean", frontendMsMean);
  kv("estimator_ms_mean", estimatorMsMean);
  kv("init_s", initSeconds);
  kv("estimator_ms_mean_before_init", estimatorMsBeforeInit);
  kv("estimator_ms_mean_after_init", estimatorMsAfterInit);
  kv("estimator_ms_median", estimatorMsMedian);
  kv("gnss_ms_per_epoch", gnssMsMean);
  kv("gnss_ms_per_frame", gnssMsPerFrame);
  kv("gnss_epochs", static_cast<double>(gnssEpochs));
  kv("gnss_epochs_updated", static_cast<double>(gnssEpochsUpdated));
  kv("gnss_epochs_fixed", static_cast<double>(gnssEpochsFixed));
  kv("precise_satellites", static_cast<double>(preciseSatellites));
  kv("antex_satellite_antennas", static_cast<double>(antexAntennas));
  kv("code_biases", static_cast<double>(codeBiases));
  kv("ssr_messages", static_cast<double>(ssrMessages));
  kv("phase_rows_used", static_cast<double>(phaseRowsUsed));
  kv("phase_rows_rejected", static_cast<double>(phaseRowsRejected));
  kv("ambiguity_states_max", static_cast<double>(ambiguityStatesMax));
  kv("code_rows_masked", static_cast<double>(codeRowsMasked));
  kv("broadcast_record_changes", static_cast<double>(recordChanges));
  kv("gnss_reacquisitions", static_cast<double>(reacquisitions));
  kv("gnss_reacquisition_rows_admitted", static_cast<double>(reacquisitionRowsAdmitted));
  kv("gnss_reacquisition_rows_excluded", static_cast<double>(reacquisitionRowsExcluded));
  kv("gnss_frame_restarts", static_cast<double>(frameRestarts));
  kv("frame_init_s", frameInitSeconds);
  kv("enu_move_s", enuMoveSeconds);
  auto acc = [&](const std::string& p, const Accuracy& a) {
    kv((p + "position_rmse_m").c_str(), a.positionRmse);
    kv((p + "horizontal_rmse_m").c_str(), a.horizontalRmse);
    kv((p + "vertical_rmse_m").c_str(), a.verticalRmse);
    kv((p + "rotation_rmse_deg").c_str(), a.rotationRmseDeg);
    kv((p + "velocity_rmse_mps").c_str(), a.velocityRmse);
    kv((p + "body_velocity_rmse_mps").c_str(), a.bodyVelocityRmse);
    kv((p + "start_aligned_position_rmse_m").c_str(), a.startAlignedPositionRmse);
    kv((p + "path_m").c_str(), a.pathLength);
    kv((p + "drift_percent").c_str(), a.driftPercent);
    kv((p + "position_nees").c_str(), a.positionNees);
    kv((p + "orientation_nees").c_str(), a.orientationNees);
    kv((p + "position_nees_first_pose").c_str(), a.positionNeesFirstPose);
    kv((p + "orientation_nees_first_pose").c_str(), a.orientationNeesFirstPose);
    kv((p + "poses").c_str(), static_cast<double>(a.poses));
  };
  acc("local_", local);
  acc("global_", global);
  const Eigen::Vector3d nan = Eigen::Vector3d::Constant(kNaN);
  const Eigen::Vector3d l = leverArm.value_or(nan);
  kv("lever_arm_x_m", l.x());
  kv("lever_arm_y_m", l.y());
  kv("lever_arm_z_m", l.z());
  kv("lever_arm_error_m", leverArm && leverArmTruth ? (*leverArm - *leverArmTruth).norm() : kNaN);
  kv("time_offset_ms", timeOffset ? *timeOffset * 1e3 : kNaN);
  kv("time_offset_sigma_ms", timeOffsetSigma ? *timeOffsetSigma * 1e3 : kNaN);
  kv("time_offset_error_ms", timeOffset && timeOffsetTruth ? (*timeOffset - *timeOffsetTruth) * 1e3 : kNaN);
}

void ReplaySummary::print(std::ostream& os) const {
  char b[200];
  os << "------------------------------------------------------------\n";
  auto row = [&](const char* k, const std::string& v) {  // the value streamed whole, however long
    std::snprintf(b, sizeof b, "%-30s ", k);
    os << b << v << '\n';
  };
  auto f = [&](const char* fmt, double v) {
    std::snprintf(b, sizeof b, fmt, v);
    return std::string(b);
  };
  row("camera input", cameraLess ? "none (camera-less: IMU and GNSS)" : featureTracks ? "simulated feature tracks" : "images (front end thread)");
  row("frames", std::to_string(framesProcessed) + " processed of " + std::to_string(frames) + ", " +
                    std::to_string(framesInitialized) + " initialised, " + std::to_string(framesUpdated) + " with visual update" +
                    (estimatorResets ? ", " + std::to_string(estimatorResets) + " VIO resets (lock-out)" : std::string()));
  row("IMU samples", std::to_string(imuSamples));
  row("skipped frames", std::to_string(skippedBadImages) + " unreadable images, " + std::to_string(skippedMissingImages) +
                            " missing images");
  row("IMU gaps", std::to_string(imuGaps) + " (largest " + f("%.3f", largestImuGap_s) + " s)");
  row("front end [ms/frame]", f("mean %.2f", frontendMsMean) + f(", max %.2f", frontendMsMax));
  row("estimator [ms/frame]", f("mean %.2f", estimatorMsMean) + f(", median %.2f", estimatorMsMedian) +
                                   f(", max %.2f", estimatorMsMax));
  if (!framesWaitingBy.empty()) {
    std::string w = f("%.2f s to initialise", initSeconds) + f(" (%.2f ms/frame before, ", estimatorMsBeforeInit) +
                    f("%.2f after); waiting: ", estimatorMsAfterInit);
    for (const auto& [why, count] : framesWaitingBy)
      w += std::string(vio::initStatusText(why)) + " " + std::to_string(count) + ", ";
    char k[32];
    std::snprintf(k, sizeof k, "%-30s ", "initialisation");
    os << k << w.substr(0, w.size() - 2) << '\n';
  }
  if (!gnssEpochsWaitingBy.empty()) {
    std::string w;
    for (const auto& [why, count] : gnssEpochsWaitingBy) w += why + " " + std::to_string(count) + ", ";
    row("GNSS/INS start waiting", w.substr(0, w.size() - 2) + " (epochs)");
  }
  if (gnssEpochs + gnssEpochsSkipped > 0) {
    row("GNSS epochs", std::to_string(gnssEpochs) + " processed (" + std::to_string(gnssEpochsUpdated) + " updated, " +
                           std::to_string(gnssEpochsFixed) + " RTK fixed), " + std::to_string(gnssEpochsSkipped) +
                           " before VIO initialisation" +
                           (gnssEpochsInOutage ? ", " + std::to_string(gnssEpochsInOutage) + " in simulated outages" : ""));
    row("GNSS [ms/epoch]", f("mean %.3f", gnssMsMean) + f(" (%.3f ms per frame)", gnssMsPerFrame));
    std::string products = "broadcast";
    if (folderProductsSkipped)
      products += " (differential rows cancel the orbit/clock errors; the folder's precise products were not read, "
                  "--sp3/--clk to use them)";
    if (preciseSatellites > 0) {
      products = "precise products, " + std::to_string(preciseSatellites) + " satellites";
      if (antexAntennas > 0) products += ", ANTEX " + std::to_string(antexAntennas) + " satellite antennas";
      if (codeBiases > 0) products += ", " + std::to_string(codeBiases) + " code biases";
    }
    if (ssrMessages > 0) products += std::string(preciseSatellites > 0 ? "; where they do not cover: " : " + ") +
                                     "SSR corrections (" + std::to_string(ssrMessages) + " messages)";
    row("orbits/clocks", products);
    if (phaseRowsUsed + phaseRowsRejected > 0)
      row("carrier phase (PPP)", std::to_string(phaseRowsUsed) + " rows used, " + std::to_string(phaseRowsRejected) +
                                     " gated out; up to " + std::to_string(ambiguityStatesMax) + " ambiguity states" +
                                     (recordChanges > 0 ? "; " + std::to_string(recordChanges) + " broadcast record changes carried over" : ""));
    if (codeRowsMasked > 0) row("C/N0 mask", std::to_string(codeRowsMasked) + " code rows dropped");
    if (reacquisitions > 0) {
      std::string t = std::to_string(reacquisitions) + (reacquisitions == 1 ? " recovery, " : " recoveries, ") +
                      std::to_string(reacquisitionRowsAdmitted) + " rows admitted, " +
                      std::to_string(reacquisitionRowsExcluded) + " excluded";
      if (!reacquisitionExcluded.empty()) {
        t += " (";
        for (const auto& [sat, n] : reacquisitionExcluded) t += sat.str() + (n > 1 ? "×" + std::to_string(n) : "") + " ";
        t.back() = ')';
      }
      row("GNSS re-acquisition", t);
    }
    if (frameRestarts > 0)
      row("frame restarts", std::to_string(frameRestarts) + " (a start that was not linear dropped the state; warnings)");
    if (std::isfinite(frameInitSeconds)) row("frame initialised", f("%.1f s after the first frame", frameInitSeconds));
    if (std::isfinite(enuMoveSeconds)) row("estimator in ENU", f("%.1f s after the first frame", enuMoveSeconds));
  }
  if (leverArm) {
    std::string t = f("%.3f", leverArm->x()) + f(" %.3f", leverArm->y()) + f(" %.3f m", leverArm->z());
    if (leverArmTruth) t += f(" (error %.3f m)", (*leverArm - *leverArmTruth).norm());
    row("lever arm", t);
  }
  if (timeOffset) {
    std::string t = f("%.3f ms", *timeOffset * 1e3) + f(" (sigma %.3f ms", timeOffsetSigma.value_or(0.0) * 1e3);
    if (timeOffsetTruth) t += f(", error %.3f ms", (*timeOffset - *timeOffsetTruth) * 1e3);
    row("camera-IMU time offset", t + ")");
  }
  row("dataset / wall / CPU time [s]", f("%.2f", datasetSeconds) + f(" / %.2f", wallSeconds) + f(" / %.2f", cpuSeconds));
  row("real-time factor", f("%.2fx", realTimeFactor()));
  os << "------------------------------------------------------------\n";
  if (!evaluationTable.empty()) os << "accuracy against the dataset ground truth (4-DoF aligned):\n" << evaluationTable;
  if (!globalEvaluationTable.empty())
    os << "GNSS antenna (global.pos) against the true antenna track, ENU, no alignment:\n" << globalEvaluationTable;
}

}  // namespace gvins::fusion
