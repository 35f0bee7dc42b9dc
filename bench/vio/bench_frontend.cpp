// Front-end cost per 752x480 EuRoC stereo frame (tests/data/euroc/v101_static_stereo): PNG
// decoding, equalisation + pyramids, corner detection, temporal KLT, RANSAC, stereo matching and
// the whole StereoFrontend::process(). Real time at 20 Hz is 50 ms per frame; the issue asks
// for the whole pipeline (front end + estimator) at >= 5x real time, i.e. <= 10 ms per frame.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "gvins/vio/euroc_dataset.hpp"
#include "gvins/vio/frontend.hpp"
#include "gvins/vio/image_io.hpp"

using namespace gvins::vio;

namespace {
const std::string kV101 = std::string(GVINS_TEST_DATA) + "/euroc/v101_static_stereo";

struct Clip {
  EurocDataset ds{kV101};
  std::vector<cv::Mat> left, right;
  Clip() {
    for (const auto& f : ds.frames()) {
      left.push_back(ds.loadImage(0, f.cam0));
      right.push_back(ds.loadImage(1, *f.cam1));
    }
  }
};
const Clip& clip() {
  static const Clip c;
  return c;
}

Eigen::Matrix4d inverse(const Eigen::Matrix4d& T) {
  Eigen::Matrix4d I = Eigen::Matrix4d::Identity();
  I.topLeftCorner<3, 3>() = T.topLeftCorner<3, 3>().transpose();
  I.topRightCorner<3, 1>() = -T.topLeftCorner<3, 3>().transpose() * T.topRightCorner<3, 1>();
  return I;
}

cv::Mat equalized(const cv::Mat& m) {
  cv::Mat out;
  cv::equalizeHist(m, out);
  return out;
}
}  // namespace

static void BM_DecodePngPair(benchmark::State& state) {
  // Arg 0: the bundled PNGs (re-encoded at maximum compression, which decodes ~2.5x slower);
  // arg 1: the same pixels encoded like the EuRoC originals (OpenCV's default PNG settings).
  const auto& c = clip();
  std::vector<std::uint8_t> b0, b1;
  if (state.range(0) == 0) {
    std::ifstream in0(c.ds.imagePath(0, 0), std::ios::binary), in1(c.ds.imagePath(1, 0), std::ios::binary);
    b0.assign(std::istreambuf_iterator<char>(in0), {});
    b1.assign(std::istreambuf_iterator<char>(in1), {});
  } else {
    cv::imencode(".png", c.left[0], b0);
    cv::imencode(".png", c.right[0], b1);
  }
  for (auto _ : state) {
    benchmark::DoNotOptimize(decodeGrayImage(b0, "l"));
    benchmark::DoNotOptimize(decodeGrayImage(b1, "r"));
  }
  state.counters["kB"] = static_cast<double>(b0.size() + b1.size()) / 2048.0;
  state.SetLabel(state.range(0) == 0 ? "max compression" : "default compression");
}
BENCHMARK(BM_DecodePngPair)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

static void BM_EqualizeAndPyramidsPair(benchmark::State& state) {
  // Histogram equalisation (the default) and both LK pyramids with derivatives.
  const auto& c = clip();
  const KltParams p;
  for (auto _ : state) {
    ImagePyramid a(equalized(c.left[0]), p), b(equalized(c.right[0]), p);
    benchmark::DoNotOptimize(a.levels().data());
    benchmark::DoNotOptimize(b.levels().data());
  }
}
BENCHMARK(BM_EqualizeAndPyramidsPair)->Unit(benchmark::kMillisecond);

static void BM_Detection150(benchmark::State& state) {
  const auto& c = clip();
  GridDetectorConfig cfg;
  cfg.detector = state.range(0) == 0 ? CornerDetector::Fast : CornerDetector::ShiTomasi;
  const GridDetector det(cfg);
  const cv::Mat img = equalized(c.left[0]);
  std::size_t n = 0;
  for (auto _ : state) {
    std::vector<cv::Point2f> pts;
    det.detect(img, pts);
    n = pts.size();
  }
  state.counters["features"] = static_cast<double>(n);
  state.SetLabel(state.range(0) == 0 ? "FAST" : "Shi-Tomasi");
}
BENCHMARK(BM_Detection150)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

static void BM_TemporalKlt150(benchmark::State& state) {
  const auto& c = clip();
  const KltParams p;
  const ImagePyramid a(equalized(c.left[0]), p), b(equalized(c.left[1]), p);
  std::vector<cv::Point2f> pts;
  GridDetector().detect(a.image(), pts);
  std::vector<cv::Point2f> out;
  std::vector<unsigned char> st;
  for (auto _ : state) {
    trackKlt(a, b, pts, out, st, p, false);
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["features"] = static_cast<double>(pts.size());
}
BENCHMARK(BM_TemporalKlt150)->Unit(benchmark::kMillisecond);

static void BM_FundamentalRansac150(benchmark::State& state) {
  // Undistorted cam0 -> cam1 correspondences of a real scene (non-degenerate geometry).
  const auto& c = clip();
  const CameraModel cam(c.ds.cameraCalibration(0).intrinsics);
  FeatureTracker tr(cam, FeatureTrackerConfig{});
  tr.process(ImagePyramid(equalized(c.left[0]), KltParams{}));
  const auto ids = tr.ids();
  const auto p0 = tr.points();
  tr.process(ImagePyramid(equalized(c.right[0]), KltParams{}));
  std::vector<cv::Point2f> a, b;
  for (std::size_t i = 0; i < tr.ids().size(); ++i) {
    if (tr.trackLengths()[i] < 2) continue;
    const auto k = static_cast<std::size_t>(std::find(ids.begin(), ids.end(), tr.ids()[i]) - ids.begin());
    const Eigen::Vector2d x = cam.undistort({p0[k].x, p0[k].y}) * cam.intrinsics().fx;
    const Eigen::Vector2d y = cam.undistort({tr.points()[i].x, tr.points()[i].y}) * cam.intrinsics().fx;
    a.emplace_back(static_cast<float>(x.x()), static_cast<float>(x.y()));
    b.emplace_back(static_cast<float>(y.x()), static_cast<float>(y.y()));
  }
  std::vector<unsigned char> mask;
  for (auto _ : state) benchmark::DoNotOptimize(cv::findFundamentalMat(a, b, cv::FM_RANSAC, 1.0, 0.99, mask));
  state.counters["points"] = static_cast<double>(a.size());
}
BENCHMARK(BM_FundamentalRansac150)->Unit(benchmark::kMillisecond);

static void BM_StereoMatch150(benchmark::State& state) {
  const auto& c = clip();
  const auto& c0 = c.ds.cameraCalibration(0);
  const auto& c1 = c.ds.cameraCalibration(1);
  const StereoMatcher m(CameraModel(c0.intrinsics), CameraModel(c1.intrinsics), inverse(c1.T_BS) * c0.T_BS);
  const KltParams p;
  const ImagePyramid a(equalized(c.left[0]), p), b(equalized(c.right[0]), p);
  std::vector<cv::Point2f> pts;
  GridDetector().detect(a.image(), pts);
  std::vector<unsigned char> st;
  std::size_t matched = 0;
  for (auto _ : state) {
    std::vector<cv::Point2f> right;
    m.match(a, b, pts, right, st, 2.3);
    matched = static_cast<std::size_t>(std::count(st.begin(), st.end(), 1));
  }
  state.counters["matched"] = static_cast<double>(matched);
}
BENCHMARK(BM_StereoMatch150)->Unit(benchmark::kMillisecond);

// The whole front end frame by frame (images already decoded), with the per-stage split of the
// last run printed as counters (ms).
static void BM_StereoFrontendFrame(benchmark::State& state) {
  const auto& c = clip();
  const auto c1 = c.ds.cameraCalibration(1);
  FrontendConfig cfg;
  cfg.useStereo = state.range(0) != 0;
  StereoFrontend fe(cfg, c.ds.cameraCalibration(0), &c1);
  std::size_t i = 0;
  FrontendTiming sum;
  std::size_t n = 0;
  for (auto _ : state) {
    const std::size_t k = i++ % c.left.size();
    const FeatureFrame f = fe.process(static_cast<std::int64_t>(i), c.left[k], cfg.useStereo ? c.right[k] : cv::Mat());
    sum.pyramid += f.timing.pyramid;
    sum.tracking += f.timing.tracking;
    sum.ransac += f.timing.ransac;
    sum.detection += f.timing.detection;
    sum.stereo += f.timing.stereo;
    ++n;
  }
  const double dn = static_cast<double>(n);
  state.counters["pyr_ms"] = sum.pyramid / dn;
  state.counters["klt_ms"] = sum.tracking / dn;
  state.counters["ransac_ms"] = sum.ransac / dn;
  state.counters["detect_ms"] = sum.detection / dn;
  state.counters["stereo_ms"] = sum.stereo / dn;
  state.SetLabel(cfg.useStereo ? "stereo" : "mono");
}
BENCHMARK(BM_StereoFrontendFrame)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);

int main(int argc, char** argv) {
  // OpenCV's own worker threads compete with the filter thread on small machines; the numbers
  // below are for one OpenCV thread unless GVINS_OPENCV_THREADS is set.
  const char* env = std::getenv("GVINS_OPENCV_THREADS");
  cv::setNumThreads(env ? std::atoi(env) : 1);
  std::fprintf(stderr, "OpenCV threads: %d\n", cv::getNumThreads());
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
