#include "partsim/server/sim_server.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>

#include "partsim/core/error.h"

namespace partsim {

using Clock = std::chrono::steady_clock;

SimServer::SimServer(Scene* scene, ControlLoop* loop, const SimServerOptions& options)
    : scene_(scene), loop_(loop), options_(options) {
  if (!scene_) throw Error("SimServer: scene is null");
  if (!options_.fast && !(options_.realtime_factor > 0))
    throw Error("SimServer: realtime_factor must be positive");
  dt_ = scene_->GetTimestep();
  initial_state_ = scene_->Pack();
}

SimServer::~SimServer() { Stop(); }

void SimServer::Start(bool paused) {
  if (thread_.joinable()) throw Error("SimServer: already started");
  paused_ = paused;
  stop_ = false;
  thread_ = std::thread([this] { Loop(); });
}

void SimServer::Stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void SimServer::Pause() {
  {
    // under the lock, so that the simulation thread cannot miss the change between testing
    // its wait's condition and starting to wait
    std::lock_guard<std::mutex> lock(mutex_);
    paused_ = true;
    pending_steps_ = 0;  // a pause stops a StepN burst too
  }
  cv_.notify_all();
}

void SimServer::Resume() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    paused_ = false;
    resync_ = true;
  }
  cv_.notify_all();
}

void SimServer::StepN(long long n) {
  if (n < 1 || n > kMaxStepRequest)
    throw Error("step: n must be an integer from 1 to " + std::to_string(kMaxStepRequest) +
                ", got " + std::to_string(n));
  {
    std::lock_guard<std::mutex> lock(mutex_);  // as in Pause()
    pending_steps_ = std::min(pending_steps_ + n, kMaxStepRequest);
  }
  cv_.notify_all();
}

void SimServer::Reset() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending_steps_ = 0;
  }
  Post([this] { scene_->Unpack(initial_state_); });
}

std::string SimServer::GetLastError() const {
  std::lock_guard<std::mutex> lock(error_mutex_);
  return last_error_;
}

void SimServer::RecordError(const std::string& message) {
  const long long n = ++errors_;
  {
    std::lock_guard<std::mutex> lock(error_mutex_);
    last_error_ = message;
  }
  if (n <= 20 || n % 1000 == 0)
    std::fprintf(stderr, "partsim: simulation thread: %s (error %lld; the simulation goes on)\n",
                 message.c_str(), n);
}

template <class F>
void SimServer::Guarded(const char* what, F&& f) {
  // nothing that runs on the simulation thread may end it (or the process)
  try {
    f();
  } catch (const std::exception& e) {
    RecordError(std::string(what) + ": " + e.what());
  } catch (...) {
    RecordError(std::string(what) + ": unknown exception");
  }
}

void SimServer::Post(Command command) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    queue_.push_back(std::move(command));
  }
  cv_.notify_all();
}

void SimServer::SetOptions(const SimServerOptions& options) {
  if (!options.fast && !(options.realtime_factor > 0))
    throw Error("SimServer: realtime_factor must be positive");
  std::lock_guard<std::mutex> lock(mutex_);
  options_ = options;
  resync_ = true;
}

void SimServer::RunCommands(std::unique_lock<std::mutex>& lock) {
  // run outside the lock so commands may post further commands
  std::vector<Command> pending;
  pending.swap(queue_);
  lock.unlock();
  for (Command& c : pending) {
    // once stopping, what is still queued is dropped: Stop() waits for one command at most
    if (stop_) break;
    Guarded("command", c);
    ++commands_run_;
  }
  pending.clear();  // the dropped commands' captures go on this thread, outside the lock
  lock.lock();
}

void SimServer::Loop() {
  Clock::time_point anchor_wall;
  long long anchor_steps = 0;
  // when the last paced step was due: a re-anchored clock never starts before the step after
  // it, so pauses, resumes and option changes cannot make the simulation run ahead of the wall
  Clock::time_point last_due{};
  bool paced = false;    // last_due holds the due time of a paced step
  bool stepped = false;  // since the thread last came to rest
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    RunCommands(lock);
    if (stop_) break;
    // paused with nothing to step: wait for a command, a step request or resume
    if (paused_ && pending_steps_ == 0) {
      if (stepped) {
        // come to rest: the rest callbacks see the state the scene stays in
        stepped = false;
        lock.unlock();
        for (const StepCallback& callback : rest_callbacks_)
          Guarded("rest callback", [&] { callback(clock_steps_); });
        lock.lock();
        continue;
      }
      cv_.wait(lock, [this] { return stop_ || !queue_.empty() || !paused_ || pending_steps_ > 0; });
      continue;
    }
    // paused: one of the requested steps (the count and the flag change only under the lock)
    const bool single = paused_;
    if (single) --pending_steps_;
    // pace against the wall clock
    if (!single && !options_.fast) {
      if (resync_) {
        anchor_wall = Clock::now();
        if (paced) {
          const Clock::time_point next =
              last_due + std::chrono::duration_cast<Clock::duration>(
                             std::chrono::duration<double>(dt_ / options_.realtime_factor));
          anchor_wall = std::max(anchor_wall, next);
        }
        anchor_steps = clock_steps_;
        resync_ = false;
      }
      const double sim_ahead = (clock_steps_ - anchor_steps) * dt_ / options_.realtime_factor;
      Clock::time_point due = anchor_wall + std::chrono::duration_cast<Clock::duration>(
                                                std::chrono::duration<double>(sim_ahead));
      Clock::time_point now = Clock::now();
      if (now > due + std::chrono::duration<double>(options_.max_lag)) {
        resync_ = true;  // too far behind: drop the lag
        due = now;
      } else if (due > now) {
        // wake early for commands, pause or stop
        if (cv_.wait_until(lock, due,
                           [this] { return stop_ || !queue_.empty() || paused_.load(); }))
          continue;
      }
      last_due = due;
      paced = true;
    } else {
      resync_ = true;
      paced = false;
    }
    lock.unlock();
    Guarded("step", [this] {
      if (loop_)
        loop_->Step(1);
      else
        scene_->Step(1);
    });
    const long long now_steps = ++clock_steps_;
    stepped = true;
    for (const StepCallback& callback : callbacks_)
      Guarded("step callback", [&] { callback(now_steps); });
    lock.lock();
  }
}

}  // namespace partsim
