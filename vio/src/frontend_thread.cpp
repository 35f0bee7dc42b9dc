#include "gvins/vio/frontend_thread.hpp"

namespace gvins::vio {

FrontendThread::FrontendThread(StereoFrontend frontend, std::size_t inputCapacity, std::size_t outputCapacity)
    : frontend_(std::move(frontend)), in_(inputCapacity), out_(outputCapacity), worker_([this] { run(); }) {}

FrontendThread::~FrontendThread() { stop(); }

void FrontendThread::run() {
  try {
    while (auto item = in_.pop()) {
      FeatureFrame f = frontend_.process(item->t_ns, item->left, item->right,
                                         item->R_cur_prev ? &*item->R_cur_prev : nullptr);
      if (!out_.push(std::move(f))) break;  // stopped
    }
  } catch (...) {
    {
      std::lock_guard lock(errorMutex_);
      error_ = std::current_exception();
    }
    in_.close();
    in_.clear();
  }
  out_.close();
}

bool FrontendThread::push(StereoImages images) { return in_.push(std::move(images)); }

void FrontendThread::finish() { in_.close(); }

std::optional<FeatureFrame> FrontendThread::pop() {
  auto f = out_.pop();
  if (!f) {
    std::lock_guard lock(errorMutex_);
    if (error_) {
      std::exception_ptr e = error_;
      error_ = nullptr;  // report once
      std::rethrow_exception(e);
    }
  }
  return f;
}

void FrontendThread::stop() {
  in_.close();
  in_.clear();
  out_.close();
  out_.clear();
  if (worker_.joinable()) worker_.join();
}

}  // namespace gvins::vio
