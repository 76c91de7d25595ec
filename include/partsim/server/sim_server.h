// Asynchronous mode: a Scene stepped on its own thread in real time, at a real-time factor or
// as fast as possible, with a monotonic clock and a thread-safe command queue. Commands posted
// from any thread run on the simulation thread between two steps, so they take effect at the
// simulation time at which they arrive.
#pragma once

#include <atomic>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "partsim/physics/scene.h"
#include "partsim/robot/controllers.h"

namespace partsim {

/// How fast the simulation thread steps.
struct SimServerOptions {
  /// Simulated seconds per wall-clock second; 1 is real time. Ignored when `fast` is set.
  double realtime_factor = 1.0;
  bool fast = false;  ///< step as fast as possible
  /// Falling behind the wall clock by more than this (s) drops the lag instead of catching up.
  double max_lag = 0.1;
};

/// Runs a Scene (and an optional ControlLoop over it) on its own thread. Every scene access from
/// other threads must go through Post(); the step callback runs on the simulation thread.
class SimServer {
 public:
  /// A command run on the simulation thread between two steps.
  using Command = std::function<void()>;
  /// Called on the simulation thread after every step with the clock (steps since Start).
  using StepCallback = std::function<void(long long clock_steps)>;

  /// `scene` (and `loop`, which may be null) must outlive the server. The state at construction
  /// is what Reset() goes back to.
  SimServer(Scene* scene, ControlLoop* loop, const SimServerOptions& options = {});
  ~SimServer();
  SimServer(const SimServer&) = delete;
  SimServer& operator=(const SimServer&) = delete;

  /// Starts the thread, running unless `paused`. Throws partsim::Error if already started.
  void Start(bool paused = false);
  /// Stops and joins the thread: a command or step under way finishes, the commands still
  /// queued are dropped without running (destroyed on the simulation thread). Idempotent.
  void Stop();
  void Pause();
  /// Resumes stepping; in real time, never ahead of the wall clock: the first step after a
  /// resume is due no earlier than one step after the last paced step was.
  void Resume();
  bool IsPaused() const { return paused_; }
  /// Most steps one StepN may ask for, and most steps waiting at once.
  static constexpr long long kMaxStepRequest = 1000000;
  /// While paused: advances exactly n steps, then stays paused. Running: no effect. Throws
  /// partsim::Error unless 1 <= n <= kMaxStepRequest; steps already waiting count towards the
  /// bound (the excess is dropped). Pause() and Reset() cancel the steps still waiting.
  void StepN(long long n);
  /// Steps asked for by StepN and not taken yet.
  long long GetPendingSteps() const { return pending_steps_; }
  /// Restores the state from construction (queued like a command). The clock keeps counting.
  void Reset();
  /// Queues a command; it runs before the next step (or at once while paused).
  void Post(Command command);
  /// Adds a callback run after every step, in the order added (before Start).
  void AddStepCallback(StepCallback callback) { callbacks_.push_back(std::move(callback)); }
  /// Adds a callback run once each time the thread comes to rest after stepping: paused with
  /// no steps waiting (after a pause, or the last step of a StepN), in the order added (before
  /// Start). The state it sees is the one the scene stays in.
  void AddRestCallback(StepCallback callback) { rest_callbacks_.push_back(std::move(callback)); }
  void SetOptions(const SimServerOptions& options);

  /// Monotonic clock: steps taken since Start (Reset does not rewind it), and in seconds.
  long long GetClockSteps() const { return clock_steps_; }
  double GetClockSeconds() const { return clock_steps_ * dt_; }
  double GetTimestep() const { return dt_; }
  /// Commands run so far.
  long long GetCommandsRun() const { return commands_run_; }
  /// Errors on the simulation thread so far: a command, a step or a step callback that threw.
  /// The thread goes on; each error is written to stderr (the first 20, then every 1000th).
  long long GetErrorCount() const { return errors_; }
  /// The last such error's message ("" if none).
  std::string GetLastError() const;

 private:
  void Loop();
  void RunCommands(std::unique_lock<std::mutex>& lock);
  /// Runs `f` on the simulation thread, recording what it throws as an error of `what`.
  template <class F>
  void Guarded(const char* what, F&& f);
  void RecordError(const std::string& message);
  Scene* scene_;
  ControlLoop* loop_;
  SimServerOptions options_;
  double dt_;
  std::vector<char> initial_state_;
  std::vector<StepCallback> callbacks_;
  std::vector<StepCallback> rest_callbacks_;
  std::thread thread_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<Command> queue_;
  std::atomic<bool> stop_{false};  ///< written under mutex_
  bool resync_ = true;             ///< re-anchor the wall clock at the next step
  std::atomic<bool> paused_{false};
  std::atomic<long long> pending_steps_{0};
  std::atomic<long long> clock_steps_{0};
  std::atomic<long long> commands_run_{0};
  std::atomic<long long> errors_{0};
  mutable std::mutex error_mutex_;
  std::string last_error_;
};

}  // namespace partsim
