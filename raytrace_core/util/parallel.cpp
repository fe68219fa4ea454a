// parallel_for and the thread cap on oneTBB. Work items are coarse (image tiles, photon batches,
// patch rows), so ranges may be split down to a single index (grain 1); TBB's auto partitioner
// splits further wherever threads run idle and steal work.

#include "raytrace_core/util/parallel.h"

#include "raytrace_core/util/error.h"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/global_control.h>
#include <oneapi/tbb/info.h>
#include <oneapi/tbb/parallel_for.h>

#include <atomic>
#include <optional>

#include <pmmintrin.h>
#include <xmmintrin.h>

namespace gilt::raytrace_core::util {

/// Holds the TBB control object that caps the parallelism while it lives.
struct ThreadLimitImpl {
  std::optional<tbb::global_control> control;
};

ThreadLimit::ThreadLimit(int threads) : impl_(std::make_unique<ThreadLimitImpl>()) {
  if (threads > 0) {
    impl_->control.emplace(tbb::global_control::max_allowed_parallelism, static_cast<size_t>(threads));
  }
}

ThreadLimit::~ThreadLimit() = default;

namespace {

/// Set by request_stop(). Lock-free, so a signal handler may set it.
std::atomic<bool> stop_flag{false};
static_assert(std::atomic<bool>::is_always_lock_free);

/// Sets flush-to-zero and denormals-are-zero for its lifetime, then restores the previous mode.
/// Embree asks for this mode on every thread that traces rays, and TBB threads that built an
/// Embree scene already have it; setting it on every task makes arithmetic, and so every
/// result, the same whichever thread runs the task.
class DenormalsAreZero {
 public:
  DenormalsAreZero() : saved_(_mm_getcsr()) {
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
  }
  ~DenormalsAreZero() { _mm_setcsr(saved_); }

 private:
  unsigned saved_;
};

}  // namespace

void parallel_for(size_t count, const std::function<void(size_t)>& body) {
  if (count == 0) return;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 1),
                    [&body](const tbb::blocked_range<size_t>& range) {
                      const DenormalsAreZero mode;
                      for (size_t i = range.begin(); i != range.end(); ++i) {
                        // TBB cancels the loop's other tasks and rethrows in the caller.
                        if (stop_flag.load(std::memory_order_relaxed)) throw Interrupted();
                        body(i);
                      }
                    });
  if (stop_flag.load(std::memory_order_relaxed)) throw Interrupted();
}

void request_stop() noexcept { stop_flag.store(true, std::memory_order_relaxed); }
void clear_stop() noexcept { stop_flag.store(false, std::memory_order_relaxed); }
bool stop_requested() noexcept { return stop_flag.load(std::memory_order_relaxed); }

int hardware_threads() { return tbb::info::default_concurrency(); }

}  // namespace gilt::raytrace_core::util
