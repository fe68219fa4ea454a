#pragma once
// The one parallel-for abstraction of gilt, on oneTBB.

#include <cstddef>
#include <functional>
#include <memory>

namespace gilt::raytrace_core {

/// Caps the worker threads for its lifetime (0 = all hardware threads). Results never depend on
/// the count: work items are seeded by index, not by thread.
class ThreadLimit {
 public:
  explicit ThreadLimit(int threads);
  ~ThreadLimit();
  ThreadLimit(const ThreadLimit&) = delete;
  ThreadLimit& operator=(const ThreadLimit&) = delete;

 private:
  std::unique_ptr<struct ThreadLimitImpl> impl_;
};

/// Calls body(i) for every i in [0, count), in parallel, with dynamic load balancing.
void parallel_for(size_t count, const std::function<void(size_t)>& body);

/// Number of hardware threads available.
int hardware_threads();

}  // namespace gilt::raytrace_core
