// gvins-imu: IMU logs of other layouts (column order, units, mounting, GPST or counter time with
// an RTKLIB time-tag file) read and written as a dataset's EuRoC imu0/data.csv.
#include <cmath>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "gvins/base/command_line.hpp"
#include "gvins/base/parse_error.hpp"
#include "gvins/sim/dataset_writer.hpp"
#include "gvins/vio/imu_table.hpp"
#include "gvins/vio/rtklib_time_tag.hpp"

namespace {

const char* kUsage =
    "usage: gvins-imu info IMU_LOG [FORMAT OPTIONS]\n"
    "       gvins-imu convert IMU_LOG -o OUT.csv [FORMAT OPTIONS]\n"
    "\n"
    "info     samples, time span, median interval, at-rest specific force and gyro bias (first\n"
    "         second), and for counter logs the clock fit to the time tags.\n"
    "convert  writes OUT.csv as a EuRoC/ASL imu0/data.csv (GPST ns, rad/s, m/s^2), the IMU file\n"
    "         of a dataset folder that gvins-replay reads (docs/dataset_format.md).\n"
    "\n"
    "FORMAT OPTIONS\n"
    "  --columns SPEC     fields of a line in order: t, ax, ay, az, gx, gy, gz, - (ignored);\n"
    "                     default t,gx,gy,gz,ax,ay,az (EuRoC). Commas or blanks separate fields.\n"
    "  --time KIND        gpst-ns (default), gpst-s (s since 1980-01-06), gpst-unix-s (s since\n"
    "                     1970-01-01 on the GPST scale), counter-ms (device counter; needs --tag)\n"
    "  --tag FILE         RTKLIB time-tag file of the log (str2str -t): places a counter on GPST\n"
    "  --accel-unit U     m/s2 (default) or g (9.80665 m/s^2)\n"
    "  --gyro-unit U      rad/s (default) or deg/s\n"
    "  --rotate R,P,Y     mounting: roll, pitch, yaw (deg) turning the log's axes into the output\n"
    "                     frame, v_out = Rz(Y) Ry(P) Rx(R) v_in (default 0,0,0)\n"
    "\n"
    "A cut-off first or last line (a log started or stopped mid-line) is skipped and counted; any\n"
    "other malformed line stops the run naming file, line and field.\n"
    "Exit status: 0 success, 1 bad input file or write error, 2 bad arguments.\n";

struct Args {
  std::string command, input, output, tag;
  gvins::vio::ImuTableFormat format;
};

void printReport(std::FILE* out, const std::string& input, const std::vector<gvins::vio::ImuSample>& s,
                 const gvins::vio::ImuTableReport& r) {
  std::fprintf(out, "file               %s\n", input.c_str());
  std::fprintf(out, "samples            %zu of %zu lines (cut-off lines skipped %zu, after the last tag %zu)\n",
               r.samples, r.lines, r.truncatedSkipped, r.untaggedSkipped);
  if (s.empty()) return;
  const double span = static_cast<double>(s.back().t_ns - s.front().t_ns) * 1e-9;
  std::fprintf(out, "time               %.3f .. %.3f s GPST since 1980-01-06 (%.3f s)\n", s.front().t_ns * 1e-9,
               s.back().t_ns * 1e-9, span);
  std::fprintf(out, "median interval    %.4f s (%.1f Hz)\n", r.medianPeriod_s,
               r.medianPeriod_s > 0.0 ? 1.0 / r.medianPeriod_s : 0.0);
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), g = Eigen::Vector3d::Zero();
  std::size_t n = 0;
  for (const auto& x : s) {
    if (x.t_ns - s.front().t_ns > 1'000'000'000) break;
    a += x.accel;
    g += x.gyro;
    ++n;
  }
  a /= static_cast<double>(n);
  g /= static_cast<double>(n);
  std::fprintf(out, "first second mean  accel %.4f %.4f %.4f m/s^2 (|a| %.4f), gyro %.5f %.5f %.5f rad/s\n", a.x(),
               a.y(), a.z(), a.norm(), g.x(), g.y(), g.z());
  if (r.counterFit) {
    std::fprintf(out, "counter clock      drift %.1f ppm; tag latency median %.1f ms, max %.1f ms%s\n",
                 r.counterDrift_ppm, r.tagLatencyMedian_ms, r.tagLatencyMax_ms,
                 r.tagOffsetsCountCrLf ? "; the tags count CR LF line ends the file has lost" : "");
  }
}

}  // namespace

int main(int argc, char** argv) {
  using namespace gvins::vio;
  Args a;
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h") {
    std::fputs(kUsage, args.empty() ? stderr : stdout);
    return args.empty() ? 2 : 0;
  }
  a.command = args[0];
  gvins::CommandLine cl("gvins-imu", kUsage, argc, argv, 2);
  if (a.command != "info" && a.command != "convert") cl.error("unknown command '" + a.command + "'");
  while (cl.next()) {
    if (cl.is("-o")) a.output = cl.value();
    else if (cl.is("--columns") || cl.is("--time")) {
      const std::string o = cl.arg(), v = cl.value();
      try {
        if (o == "--columns") a.format.columns = parseImuColumns(v);
        else a.format.time = parseImuTimeKind(v);
      } catch (const std::invalid_argument& e) {
        cl.error(o + ": " + e.what());
      }
    } else if (cl.is("--tag")) a.tag = cl.value();
    else if (cl.is("--accel-unit")) a.format.accelScale = cl.choice({"g", "m/s2"}) == "g" ? 9.80665 : 1.0;
    else if (cl.is("--gyro-unit")) a.format.gyroScale = cl.choice({"deg/s", "rad/s"}) == "deg/s" ? M_PI / 180.0 : 1.0;
    else if (cl.is("--rotate")) {
      const Eigen::Vector3d rpy = cl.vector3(-360.0, 360.0, "deg");
      a.format.rotation = rotationFromRollPitchYaw(rpy.x(), rpy.y(), rpy.z());
    } else if (a.input.empty()) a.input = cl.operand();
    else cl.error(cl.isOption() ? "unknown option '" + cl.arg() + "'" : "unexpected argument '" + cl.arg() + "'");
  }
  if (a.input.empty()) cl.error("no IMU log given");
  if (a.command == "convert" && a.output.empty()) cl.error("convert needs -o OUT.csv");
  if (a.format.time == ImuTimeKind::CounterMs && a.tag.empty()) cl.error("--time counter-ms needs --tag FILE");
  try {
    std::optional<RtklibTimeTag> tag;
    if (!a.tag.empty()) tag = RtklibTimeTag::read(a.tag);
    ImuTableReport rep;
    const auto samples = readImuTable(a.input, a.format, tag ? &*tag : nullptr, &rep);
    if (samples.empty()) {
      std::fprintf(stderr, "gvins-imu: %s holds no IMU sample\n", a.input.c_str());
      return 1;
    }
    if (a.command == "info") {
      printReport(stdout, a.input, samples, rep);
      return 0;
    }
    gvins::sim::writeImuCsv(a.output, samples);
    printReport(stderr, a.input, samples, rep);
    std::fprintf(stderr, "wrote              %s\n", a.output.c_str());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gvins-imu: %s\n", e.what());
    return 1;
  }
}
