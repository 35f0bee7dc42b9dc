// Runs a StereoFrontend on its own thread. Producers push stereo image pairs into a bounded input
// queue (blocking when the front end falls behind, so memory stays bounded); the filter pulls
// FeatureFrames from a bounded output queue. finish() lets the worker drain the input and then
// ends the output; stop() (and the destructor) abort at once. An exception in the front end
// stops the worker and is rethrown by the next pop().
#pragma once

#include <cstdint>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "gvins/vio/bounded_queue.hpp"
#include "gvins/vio/frontend.hpp"

namespace gvins::vio {

struct StereoImages {
  std::int64_t t_ns = 0;
  cv::Mat left, right;  ///< 8-bit gray; right empty for mono
  std::optional<Eigen::Matrix3d> R_cur_prev;  ///< optional gyro rotation prediction (cam0)
};

class FrontendThread {
 public:
  FrontendThread(StereoFrontend frontend, std::size_t inputCapacity = 4, std::size_t outputCapacity = 8);
  ~FrontendThread();
  FrontendThread(const FrontendThread&) = delete;
  FrontendThread& operator=(const FrontendThread&) = delete;

  /// Blocks while the input queue is full; false if the thread was stopped or failed.
  bool push(StereoImages images);
  /// No more input: the worker processes what is queued, then pop() returns std::nullopt.
  void finish();
  /// Next result in input order; blocks; std::nullopt after finish() once all are delivered or
  /// after stop(). Rethrows an exception raised by the front end.
  std::optional<FeatureFrame> pop();
  /// Abort: discards queued input and output and joins the worker.
  void stop();

 private:
  void run();
  StereoFrontend frontend_;
  BoundedQueue<StereoImages> in_;
  BoundedQueue<FeatureFrame> out_;
  std::mutex errorMutex_;
  std::exception_ptr error_;
  std::thread worker_;
};

}  // namespace gvins::vio
