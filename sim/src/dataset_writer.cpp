#include "gvins/sim/dataset_writer.hpp"

#include <charconv>
#include <cstring>
#include <stdexcept>

#include <Eigen/Geometry>

#include "gvins/base/geodetic.hpp"

namespace gvins::sim {

TextFile::TextFile(const std::filesystem::path& path) : path_(path) {
  f_ = std::fopen(path.string().c_str(), "wb");
  if (!f_) throw std::runtime_error("cannot create " + path.string());
  std::setvbuf(f_, nullptr, _IOFBF, 1 << 16);
}

TextFile::~TextFile() {
  if (f_) std::fclose(f_);
}

void TextFile::write(const char* p, std::size_t n) {
  if (!f_ || std::fwrite(p, 1, n, f_) != n) throw std::runtime_error("write error on " + path_.string());
}
TextFile& TextFile::operator<<(const std::string& s) {
  write(s.data(), s.size());
  return *this;
}
TextFile& TextFile::operator<<(const char* s) {
  write(s, std::strlen(s));
  return *this;
}
TextFile& TextFile::num(double v) {
  char buf[40];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  write(buf, static_cast<std::size_t>(r.ptr - buf));
  return *this;
}
TextFile& TextFile::integer(std::int64_t v) {
  char buf[24];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  write(buf, static_cast<std::size_t>(r.ptr - buf));
  return *this;
}
TextFile& TextFile::unsignedInteger(std::uint64_t v) {
  char buf[24];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  write(buf, static_cast<std::size_t>(r.ptr - buf));
  return *this;
}
TextFile& TextFile::fixed(double v, int decimals) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed, decimals);
  if (r.ec != std::errc()) throw std::runtime_error("number too large for " + path_.string());
  write(buf, static_cast<std::size_t>(r.ptr - buf));
  return *this;
}
TextFile& TextFile::put(char c) {
  write(&c, 1);
  return *this;
}
void TextFile::close() {
  if (!f_) return;
  const bool ok = std::fflush(f_) == 0 && !std::ferror(f_);
  std::fclose(f_);
  f_ = nullptr;
  if (!ok) throw std::runtime_error("write error on " + path_.string());
}

std::string formatDouble(double v) {
  char buf[40];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

namespace {

Eigen::Vector4d quaternionWxyz(const Eigen::Matrix3d& R) {
  Eigen::Quaterniond q(R);
  q.normalize();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  return {q.w(), q.x(), q.y(), q.z()};
}

void writeMatrix4(TextFile& f, const Eigen::Matrix4d& T) {
  f << "T_BS:\n  cols: 4\n  rows: 4\n  data: [";
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      f.num(T(r, c));
      if (r < 3 || c < 3) f << ", ";
    }
    if (r < 3) f << "\n         ";
  }
  f << "]\n";
}

}  // namespace

void writeImuCsv(const std::filesystem::path& path, const std::vector<vio::ImuSample>& samples) {
  TextFile f(path);
  f << "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],"
       "a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n";
  for (const auto& s : samples) {
    f.integer(s.t_ns);
    for (int i = 0; i < 3; ++i) f.put(',').num(s.gyro[i]);
    for (int i = 0; i < 3; ++i) f.put(',').num(s.accel[i]);
    f.put('\n');
  }
  f.close();
}

void writeImuSensorYaml(const std::filesystem::path& path, const vio::ImuNoise& noise, double rateHz,
                        const std::string& comment) {
  TextFile f(path);
  f << "%YAML:1.0\nsensor_type: imu\ncomment: \"" << comment << "\"\n\n# Sensor extrinsics wrt. the body-frame.\n";
  writeMatrix4(f, Eigen::Matrix4d::Identity());
  f << "rate_hz: ";
  f.num(rateHz);
  f << "\n\n# inertial sensor noise model parameters (Kalibr/EuRoC convention)\n";
  f << "gyroscope_noise_density: ";
  f.num(noise.gyroscope_noise_density) << "     # [ rad / s / sqrt(Hz) ]\n";
  f << "gyroscope_random_walk: ";
  f.num(noise.gyroscope_random_walk) << "       # [ rad / s^2 / sqrt(Hz) ]\n";
  f << "accelerometer_noise_density: ";
  f.num(noise.accelerometer_noise_density) << "  # [ m / s^2 / sqrt(Hz) ]\n";
  f << "accelerometer_random_walk: ";
  f.num(noise.accelerometer_random_walk) << "    # [ m / s^3 / sqrt(Hz) ]\n";
  f.close();
}

void writeCameraSensorYaml(const std::filesystem::path& path, const vio::CameraCalibration& camera, double rateHz,
                           const std::string& comment) {
  const vio::CameraIntrinsics& k = camera.intrinsics;
  TextFile f(path);
  f << "%YAML:1.0\nsensor_type: camera\ncomment: \"" << comment << "\"\n\n# Sensor extrinsics wrt. the body-frame.\n";
  writeMatrix4(f, camera.T_BS);
  f << "\n# Camera specific definitions.\nrate_hz: ";
  f.num(rateHz);
  f << "\nresolution: [";
  f.integer(k.width) << ", ";
  f.integer(k.height) << "]\ncamera_model: pinhole\nintrinsics: [";
  f.num(k.fx) << ", ";
  f.num(k.fy) << ", ";
  f.num(k.cx) << ", ";
  f.num(k.cy) << "] #fu, fv, cu, cv\ndistortion_model: ";
  f << (k.model == vio::DistortionModel::Equidistant ? "equidistant" : "radial-tangential");
  f << "\ndistortion_coefficients: [";
  for (int i = 0; i < 4; ++i) {
    f.num(k.model == vio::DistortionModel::None ? 0.0 : k.distortion[static_cast<std::size_t>(i)]);
    if (i < 3) f << ", ";
  }
  f << "]\n";
  f.close();
}

void writeCameraCsv(const std::filesystem::path& path, const std::vector<std::int64_t>& stamps) {
  TextFile f(path);
  f << "#timestamp [ns],filename\n";
  for (const std::int64_t t : stamps) {
    f.integer(t).put(',').integer(t) << ".png\n";
  }
  f.close();
}

void writeGroundTruthCsv(const std::filesystem::path& path, const std::vector<TruthRow>& rows) {
  TextFile f(path);
  f << "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z [], "
       "v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], b_w_RS_S_y [rad s^-1], "
       "b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], b_a_RS_S_z [m s^-2]\n";
  for (const TruthRow& r : rows) {
    const Eigen::Vector4d q = quaternionWxyz(r.state.R_WB);
    f.integer(r.t_ns);
    for (int i = 0; i < 3; ++i) f.put(',').num(r.state.p_WB[i]);
    for (int i = 0; i < 4; ++i) f.put(',').num(q[i]);
    for (int i = 0; i < 3; ++i) f.put(',').num(r.state.v_WB[i]);
    for (int i = 0; i < 3; ++i) f.put(',').num(r.bg[i]);
    for (int i = 0; i < 3; ++i) f.put(',').num(r.ba[i]);
    f.put('\n');
  }
  f.close();
}

void writeEcefTruthCsv(const std::filesystem::path& path, const std::vector<TruthRow>& rows, const LocalFrame& frame,
                       const Eigen::Vector3d& leverArm) {
  const Eigen::Matrix3d R_EW = frame.rotationEcefFromW();
  TextFile f(path);
  f << "#timestamp [ns],p_E_x [m],p_E_y [m],p_E_z [m],v_E_x [m s^-1],v_E_y [m s^-1],v_E_z [m s^-1],"
       "q_EB_w [],q_EB_x [],q_EB_y [],q_EB_z [],antenna_E_x [m],antenna_E_y [m],antenna_E_z [m],"
       "antenna_v_E_x [m s^-1],antenna_v_E_y [m s^-1],antenna_v_E_z [m s^-1],antenna_lat [deg],antenna_lon [deg],"
       "antenna_h [m]\n";
  for (const TruthRow& r : rows) {
    const Eigen::Vector3d p = frame.toEcef(r.state.p_WB);
    const Eigen::Vector3d v = R_EW * r.state.v_WB;
    const Eigen::Vector4d q = quaternionWxyz(R_EW * r.state.R_WB);
    const Eigen::Vector3d pa = frame.toEcef(r.state.pointPosition(leverArm));
    const Eigen::Vector3d va = R_EW * r.state.pointVelocity(leverArm);
    const Geodetic g = ecefToGeodetic(pa);
    f.integer(r.t_ns);
    for (int i = 0; i < 3; ++i) f.put(',').num(p[i]);
    for (int i = 0; i < 3; ++i) f.put(',').num(v[i]);
    for (int i = 0; i < 4; ++i) f.put(',').num(q[i]);
    for (int i = 0; i < 3; ++i) f.put(',').num(pa[i]);
    for (int i = 0; i < 3; ++i) f.put(',').num(va[i]);
    f.put(',').num(g.lat * 57.29577951308232).put(',').num(g.lon * 57.29577951308232).put(',').num(g.height);
    f.put('\n');
  }
  f.close();
}

void writeCameraPosesCsv(const std::filesystem::path& path, const std::vector<std::int64_t>& stamps,
                         const std::vector<Eigen::Matrix3d>& R_WC, const std::vector<Eigen::Vector3d>& p_WC) {
  TextFile f(path);
  f << "#timestamp [ns],p_WC_x [m],p_WC_y [m],p_WC_z [m],q_WC_w [],q_WC_x [],q_WC_y [],q_WC_z []\n";
  for (std::size_t i = 0; i < stamps.size(); ++i) {
    const Eigen::Vector4d q = quaternionWxyz(R_WC[i]);
    f.integer(stamps[i]);
    for (int k = 0; k < 3; ++k) f.put(',').num(p_WC[i][k]);
    for (int k = 0; k < 4; ++k) f.put(',').num(q[k]);
    f.put('\n');
  }
  f.close();
}

}  // namespace gvins::sim
