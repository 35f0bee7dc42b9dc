// The outputs of a gvins-rtk post-processing run: the RTKLIB-style .pos file (header from the
// options and the configuration, rows of the valid solutions) and the optional NMEA and KML
// files. All are written under temporary names and renamed only when the run succeeds: a failed
// run leaves no file that looks valid (and an older file of that name intact).
#pragma once

#include <memory>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "gvins/base/atomic_output_file.hpp"
#include "gvins/gnss/pos_writer.hpp"
#include "gvins/gnss/rtk.hpp"
#include "gvins/gnss/rtk_config.hpp"
#include "gvins/gnss/solution_outputs.hpp"
#include "rtk_options.hpp"

namespace gvins::rtkapp {

/// The base antenna position the solver uses and where it came from.
struct BaseLocation {
  std::optional<Eigen::Vector3d> position;
  std::string source = "command line";
};

/// "GRECJ" of a system selection ("-" for none).
std::string systemsText(const std::array<bool, kNumSystems>& systems);

class RtkOutput {
 public:
  /// Opens the files of -o, --nmea and --kml; throws std::runtime_error naming a file that
  /// cannot be created.
  RtkOutput(const RtkOptions& args, const RtkConfig& cfg);

  /// Writes a valid solution. The first one completes the .pos header with the base position
  /// (known by then, or never).
  void write(const RtkSolution& sol, const BaseLocation& base);

  /// Ends the run with `exitCode` (0: success): an empty run still gets the .pos header; the
  /// files are renamed into place on success, else discarded. Returns the exit code, 1 when
  /// finishing a file failed (message printed).
  int finish(int exitCode);

 private:
  std::string path_;
  OutputTarget pos_;
  SolutionOutputs side_;
  PosWriterOptions options_;
  std::unique_ptr<PosWriter> writer_;
};

}  // namespace gvins::rtkapp
