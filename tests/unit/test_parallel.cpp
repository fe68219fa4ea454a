// parallel_for visits every index exactly once, whatever the thread cap.

#include "raytrace_core/util/parallel.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <memory>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>

namespace gilt::raytrace_core::util {
namespace {

/// Runs parallel_for over `count` indices and checks each was visited once; returns the number of
/// distinct threads that ran the body.
size_t check_each_index_once(size_t count) {
  std::unique_ptr<std::atomic<int>[]> visits(new std::atomic<int>[count + 1]);
  for (size_t i = 0; i <= count; ++i) visits[i] = 0;
  std::mutex mutex;
  std::set<std::thread::id> threads;
  parallel_for(count, [&](size_t i) {
    ++visits[std::min(i, count)];  // an index past the end lands in the sentinel slot
    std::lock_guard lock(mutex);
    threads.insert(std::this_thread::get_id());
  });
  for (size_t i = 0; i < count; ++i) EXPECT_EQ(visits[i].load(), 1) << "index " << i << " of " << count;
  EXPECT_EQ(visits[count].load(), 0) << "indices past the end were visited";
  return threads.size();
}

TEST(Parallel, VisitsEachIndexOnceWithOneThread) {
  ThreadLimit limit(1);
  for (size_t count : {0, 1, 1000}) {
    SCOPED_TRACE(count);
    EXPECT_LE(check_each_index_once(count), 1u);
  }
}

TEST(Parallel, VisitsEachIndexOnceWithTwoThreads) {
  ThreadLimit limit(2);
  for (size_t count : {0, 1, 1000}) {
    SCOPED_TRACE(count);
    EXPECT_LE(check_each_index_once(count), 2u);
  }
}

TEST(Parallel, VisitsEachIndexOnceWithoutALimit) {
  ThreadLimit limit(0);
  for (size_t count : {0, 1, 1000}) {
    SCOPED_TRACE(count);
    check_each_index_once(count);
  }
}

TEST(Parallel, ExceptionsReachTheCaller) {
  EXPECT_THROW(parallel_for(100,
                            [](size_t i) {
                              if (i == 37) throw std::runtime_error("item 37 failed");
                            }),
               std::runtime_error);
}

TEST(Parallel, ReportsAtLeastOneHardwareThread) { EXPECT_GE(hardware_threads(), 1); }

}  // namespace
}  // namespace gilt::raytrace_core::util
