// A few threads that stay alive between jobs, for work split into parts that must start sooner
// than a new thread would (a rendered frame's post-processing: tens of microseconds).
#pragma once

#include <algorithm>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace partsim::internal {

/// Runs the parts of one job at a time on `threads` worker threads, started on the first job and
/// joined by the destructor (which first waits for a job still running). Start() hands the parts
/// out and returns at once, so that the caller can do other work; Wait() runs on the calling thread
/// whatever parts no worker has begun, then blocks until every part is done. Not for use from
/// several threads at once.
class WorkerPool {
 public:
  explicit WorkerPool(int threads) : size_(threads < 1 ? 1 : threads) {}
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  ~WorkerPool() {
    Wait();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    work_.notify_all();
    for (std::thread& t : threads_) t.join();
  }

  int size() const { return size_; }

  /// Starts part(0) ... part(parts - 1) on the workers. `part` must not throw, and must stay
  /// valid until Wait() returns. A job started before the last one was waited for is waited for
  /// first.
  void Start(int parts, std::function<void(int)> part) {
    Wait();
    if (threads_.empty()) StartThreads();  // may throw std::system_error: nothing started then
    {
      std::lock_guard<std::mutex> lock(mutex_);
      part_ = std::move(part);
      next_ = 0;
      parts_ = parts;
      pending_ = parts;
    }
    // wake only as many workers as there are parts (each wake-up costs a few microseconds)
    for (int i = 0; i < std::min(parts, size_); ++i) work_.notify_one();
  }

  /// Runs the parts not yet begun on this thread, then waits for the others.
  void Wait() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (next_ < parts_) RunOne(&lock);
    done_.wait(lock, [this] { return pending_ == 0; });
    part_ = nullptr;
  }

 private:
  void StartThreads() {
    try {
      for (int i = 0; i < size_; ++i) threads_.emplace_back([this] { Work(); });
    } catch (...) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        stop_ = true;
      }
      work_.notify_all();
      for (std::thread& t : threads_) t.join();
      threads_.clear();
      stop_ = false;
      throw;
    }
  }

  // takes the next part and runs it with the lock released (called with `lock` held)
  void RunOne(std::unique_lock<std::mutex>* lock) {
    int k = next_++;
    lock->unlock();
    part_(k);
    lock->lock();
    if (--pending_ == 0) done_.notify_all();
  }

  void Work() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      work_.wait(lock, [this] { return stop_ || next_ < parts_; });
      if (stop_) return;
      RunOne(&lock);
    }
  }

  const int size_;
  std::vector<std::thread> threads_;
  std::mutex mutex_;
  std::condition_variable work_, done_;
  std::function<void(int)> part_;
  int next_ = 0, parts_ = 0, pending_ = 0;
  bool stop_ = false;
};

}  // namespace partsim::internal
