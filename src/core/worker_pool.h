// A few threads that stay alive between jobs, for work split into parts that must start sooner
// than a new thread would (a rendered frame's post-processing: tens of microseconds).
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
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
///
/// With `spin` above zero, for jobs that come back to back (a simulation step every
/// millisecond): a worker that has just run a part keeps polling for the next job for up to
/// `spin` before it parks on the condition variable, and Wait() polls as long for the workers'
/// parts before it blocks. Waking a parked thread costs more than a short part on a virtual
/// machine whose idle cores the host halts. At most `spinners` workers poll at once (default:
/// the cores less one, so that the caller keeps a core), so that polling threads never take the
/// cores from the ones with work.
class WorkerPool {
 public:
  explicit WorkerPool(int threads, std::chrono::microseconds spin = std::chrono::microseconds(0),
                      int spinners = -1)
      : size_(threads < 1 ? 1 : threads),
        spin_(spin),
        max_spinners_(spinners >= 0 ? spinners : DefaultSpinners()) {}
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
      generation_.fetch_add(1, std::memory_order_release);  // seen by the polling workers
    }
    // wake only as many workers as there are parts (each wake-up costs a few microseconds)
    for (int i = 0; i < std::min(parts, size_); ++i) work_.notify_one();
  }

  /// Runs the parts not yet begun on this thread, then waits for the others.
  void Wait() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (next_ < parts_) RunOne(&lock);
    if (pending_ != 0 && spin_.count() > 0) {
      lock.unlock();
      Poll([this] { return pending_.load(std::memory_order_acquire) == 0; });
      lock.lock();
    }
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
      // poll for the next job before parking, if this worker had a part and few others poll
      if (spin_.count() > 0 && next_ >= parts_ && spinners_ < max_spinners_) {
        ++spinners_;
        const unsigned seen = generation_.load(std::memory_order_relaxed);
        lock.unlock();
        Poll([this, seen] { return generation_.load(std::memory_order_acquire) != seen; });
        lock.lock();
        --spinners_;
      }
    }
  }

  // true once `ready` is, false after `spin_` without it
  template <typename Ready>
  bool Poll(const Ready& ready) const {
    const auto until = std::chrono::steady_clock::now() + spin_;
    for (int i = 1;; ++i) {
      if (ready()) return true;
      if (i % 64 == 0 && std::chrono::steady_clock::now() >= until) return false;
#if defined(__x86_64__) || defined(__i386__)
      __builtin_ia32_pause();
#endif
    }
  }

  static int DefaultSpinners() {
    const int cores = static_cast<int>(std::thread::hardware_concurrency());
    return cores > 1 ? cores - 1 : 0;
  }

  const int size_;
  const std::chrono::microseconds spin_;
  const int max_spinners_;
  std::atomic<unsigned> generation_{0};
  int spinners_ = 0;  // workers polling now (under mutex_)
  std::vector<std::thread> threads_;
  std::mutex mutex_;
  std::condition_variable work_, done_;
  std::function<void(int)> part_;
  int next_ = 0, parts_ = 0;
  std::atomic<int> pending_{0};  // written under mutex_, read without it by Wait's polling
  bool stop_ = false;
};

}  // namespace partsim::internal
