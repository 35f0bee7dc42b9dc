// A bounded multi-producer/multi-consumer FIFO with blocking push/pop and close(): the link
// between the image reader, the front-end thread and the filter. After close(), push() fails and
// pop() returns the remaining items, then std::nullopt.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>
#include <optional>
#include <stdexcept>

namespace gvins::vio {

template <class T>
class BoundedQueue {
 public:
  explicit BoundedQueue(std::size_t capacity) : capacity_(capacity) {
    if (capacity == 0) throw std::invalid_argument("BoundedQueue: capacity must be positive");
  }

  /// Blocks while full; false (item not queued) once closed.
  bool push(T item) {
    std::unique_lock lock(m_);
    notFull_.wait(lock, [&] { return closed_ || q_.size() < capacity_; });
    if (closed_) return false;
    q_.push_back(std::move(item));
    notEmpty_.notify_one();
    return true;
  }

  /// Blocks while empty and open; std::nullopt once closed and drained.
  std::optional<T> pop() {
    std::unique_lock lock(m_);
    notEmpty_.wait(lock, [&] { return closed_ || !q_.empty(); });
    return takeLocked();
  }

  /// Non-blocking pop.
  std::optional<T> tryPop() {
    std::lock_guard lock(m_);
    return takeLocked();
  }

  void close() {
    std::lock_guard lock(m_);
    closed_ = true;
    notEmpty_.notify_all();
    notFull_.notify_all();
  }

  /// Drops all queued items (after an abort).
  void clear() {
    std::lock_guard lock(m_);
    q_.clear();
    notFull_.notify_all();
  }

  bool closed() const {
    std::lock_guard lock(m_);
    return closed_;
  }
  std::size_t size() const {
    std::lock_guard lock(m_);
    return q_.size();
  }
  std::size_t capacity() const { return capacity_; }

 private:
  std::optional<T> takeLocked() {
    if (q_.empty()) return std::nullopt;
    std::optional<T> item(std::move(q_.front()));
    q_.pop_front();
    notFull_.notify_one();
    return item;
  }

  const std::size_t capacity_;
  mutable std::mutex m_;
  std::condition_variable notEmpty_, notFull_;
  std::deque<T> q_;
  bool closed_ = false;
};

}  // namespace gvins::vio
