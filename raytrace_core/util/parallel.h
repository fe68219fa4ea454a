#pragma once
// The one parallel-for abstraction of gilt, on oneTBB.

#include <cstddef>
#include <functional>
#include <memory>

namespace gilt::raytrace_core::util {

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

/// Calls body(i) for every i in [0, count), in parallel, with dynamic load balancing. Throws
/// Interrupted (raytrace_core/util/error.h), without calling the bodies not yet started, once
/// request_stop() has been called.
void parallel_for(size_t count, const std::function<void(size_t)>& body);

/// Asks every parallel_for of the process to stop: the run in progress ends with Interrupted at
/// its next work item (an image tile, a photon batch, a row of links). Safe from a signal handler
/// or another thread. Every long loop of gilt runs through parallel_for; CGAL's remeshing does
/// not, and finishes its step first.
void request_stop() noexcept;

/// Clears a request, before the next run.
void clear_stop() noexcept;

/// Whether request_stop() was called since the last clear_stop().
bool stop_requested() noexcept;

/// Number of hardware threads available.
int hardware_threads();

}  // namespace gilt::raytrace_core::util
