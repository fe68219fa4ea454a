#pragma once
// Progress on stderr (elapsed, ETA, rate): one bar redrawn in place on a terminal; elsewhere (a
// log, a pipe) a plain line once the work has run two seconds and then every ten.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace gilt::raytrace_core::util {

/// Thread-safe progress reporting for `total` units of work.
class Progress {
 public:
  /// `unit` names what is counted ("samples", "photons"); `enabled` false silences it.
  Progress(std::string label, uint64_t total, std::string unit, bool enabled);
  ~Progress();
  /// Records `done` more units; redraws at most a few times a second.
  void advance(uint64_t done);
  /// Changes the total (time-budgeted runs learn it as they go).
  void set_total(uint64_t total);
  /// Clears the bar line; in plain lines, says how long the work took if it said anything.
  void finish();
  /// True when stderr is an interactive terminal.
  static bool stderr_is_terminal();

 private:
  void draw(bool final_draw);
  std::string label_, unit_;
  std::atomic<uint64_t> done_{0};
  std::atomic<uint64_t> total_;
  bool enabled_, terminal_;
  bool finished_ = false, drawn_ = false;
  std::chrono::steady_clock::time_point start_;
  std::atomic<int64_t> last_draw_ns_{0};
  std::mutex draw_mutex_;
};

}  // namespace gilt::raytrace_core::util
