#include "core/worker_pool.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <set>
#include <thread>
#include <vector>

namespace partsim::internal {
namespace {

TEST(WorkerPoolTest, EveryPartRunsOnceBeforeWaitReturns) {
  WorkerPool pool(3);
  EXPECT_EQ(pool.size(), 3);
  for (int parts : {1, 2, 3, 7, 64}) {
    std::vector<std::atomic<int>> runs(parts);
    pool.Start(parts, [&](int k) {
      std::this_thread::sleep_for(std::chrono::microseconds(50 * (k % 3)));
      runs[k]++;
    });
    pool.Wait();
    for (int k = 0; k < parts; ++k) EXPECT_EQ(runs[k].load(), 1) << "part " << k << " of " << parts;
  }
}

TEST(WorkerPoolTest, PartsRunBesideTheCallerUntilWait) {
  // a part that waits for the caller: it can only finish if a worker runs it while the caller
  // goes on between Start() and Wait()
  WorkerPool pool(1);
  std::atomic<bool> caller_went_on{false}, part_done{false};
  pool.Start(1, [&](int) {
    while (!caller_went_on) std::this_thread::yield();
    part_done = true;
  });
  caller_went_on = true;
  pool.Wait();
  EXPECT_TRUE(part_done);
}

TEST(WorkerPoolTest, PartsOnSeveralThreadsAndTheCallerHelpsWithTheRest) {
  WorkerPool pool(2);
  std::mutex m;
  std::set<std::thread::id> ids;
  pool.Start(200, [&](int) {
    std::this_thread::sleep_for(std::chrono::microseconds(200));
    std::lock_guard<std::mutex> lock(m);
    ids.insert(std::this_thread::get_id());
  });
  pool.Wait();
  EXPECT_GE(ids.size(), 2u);  // the workers (and the caller, in Wait, if parts were left)
  EXPECT_LE(ids.size(), 3u);
}

TEST(WorkerPoolTest, StartWaitsForTheJobBeforeAndTheDestructorForTheThreads) {
  std::atomic<int> sum{0};
  {
    WorkerPool pool(2);
    pool.Start(10, [&](int k) { sum += k; });
    pool.Start(10, [&](int k) { sum += 100 * k; });  // waits for the first job
    pool.Wait();
    EXPECT_EQ(sum.load(), 45 + 4500);
    pool.Start(4, [&](int) { sum += 1; });
  }  // the destructor waits for the started job, then stops the workers
  EXPECT_EQ(sum.load(), 45 + 4500 + 4);
  WorkerPool never_started(2);  // no threads until the first job
}

TEST(WorkerPoolTest, APollingPoolRunsEveryPartOnceJobAfterJob) {
  // polling workers and a polling Wait: jobs back to back (taken while polling) and after a pause
  // longer than the poll (taken from the condition variable) each run every part exactly once
  for (int spinners : {0, 1, 3}) {
    WorkerPool pool(3, std::chrono::microseconds(300), spinners);
    for (int job = 0; job < 200; ++job) {
      const int parts = 1 + job % 5;
      std::vector<std::atomic<int>> runs(parts);
      pool.Start(parts, [&](int k) { runs[k]++; });
      pool.Wait();
      for (int k = 0; k < parts; ++k)
        ASSERT_EQ(runs[k].load(), 1) << "job " << job << ", part " << k << ", " << spinners;
      if (job % 50 == 49) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  }  // destroyed with workers possibly still polling: they stop within the poll
}

}  // namespace
}  // namespace partsim::internal
