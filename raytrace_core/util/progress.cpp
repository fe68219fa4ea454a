// Progress bar on stderr: "label [#####.....]  42%  12.3s elapsed, ETA 17.0s, 1.2M samples/s";
// where stderr is not a terminal, the same without the bar, as plain lines.
//
// Workers call advance() concurrently. Counting is one atomic add; drawing happens at most every
// kRedrawInterval, by whichever worker first wins try_lock on the draw mutex, so no worker ever
// waits for the terminal.

#include "raytrace_core/util/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <mutex>
#include <string>
#include <utility>

namespace gilt::raytrace_core::util {

namespace {

constexpr int64_t kRedrawInterval = 200'000'000;  // ns: at most five redraws a second
constexpr int64_t kFirstLine = 2'000'000'000;     // ns: plain lines start after two seconds
constexpr int64_t kLineInterval = 10'000'000'000; // ns: and come every ten
constexpr int kBarWidth = 30;

/// Seconds as "12.3s", "4m05s" or "2h07m".
std::string format_duration(double seconds) {
  char text[32];
  if (seconds < 60.0) {
    std::snprintf(text, sizeof(text), "%.1fs", seconds);
  } else if (seconds < 3600.0) {
    const int s = static_cast<int>(seconds);
    std::snprintf(text, sizeof(text), "%dm%02ds", s / 60, s % 60);
  } else {
    const long m = static_cast<long>(seconds / 60.0);
    std::snprintf(text, sizeof(text), "%ldh%02ldm", m / 60, m % 60);
  }
  return text;
}

/// A rate with an SI suffix: "950", "12.3k", "1.2M", "3.4G".
std::string format_rate(double per_second) {
  const char* suffix = "";
  for (const char* s : {"k", "M", "G"}) {
    if (per_second < 1000.0) break;
    per_second /= 1000.0;
    suffix = s;
  }
  char text[32];
  std::snprintf(text, sizeof(text), *suffix ? "%.1f%s" : "%.0f%s", per_second, suffix);
  return text;
}

}  // namespace

Progress::Progress(std::string label, uint64_t total, std::string unit, bool enabled)
    : label_(std::move(label)),
      unit_(std::move(unit)),
      total_(total),
      enabled_(enabled),
      terminal_(stderr_is_terminal()),
      start_(std::chrono::steady_clock::now()) {}

Progress::~Progress() { finish(); }

bool Progress::stderr_is_terminal() { return ::isatty(STDERR_FILENO) == 1; }

void Progress::advance(uint64_t done) {
  done_.fetch_add(done, std::memory_order_relaxed);
  if (!enabled_) return;
  const int64_t now =
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - start_).count();
  const int64_t wait = terminal_ ? kRedrawInterval : last_draw_ns_.load(std::memory_order_relaxed) == 0 ? kFirstLine
                                                                                                       : kLineInterval;
  if (now - last_draw_ns_.load(std::memory_order_relaxed) < wait) return;
  std::unique_lock lock(draw_mutex_, std::try_to_lock);
  if (!lock.owns_lock()) return;
  // Another worker may have drawn between the check above and taking the lock.
  if (now - last_draw_ns_.load(std::memory_order_relaxed) < wait) return;
  last_draw_ns_.store(now, std::memory_order_relaxed);
  draw(false);
}

void Progress::set_total(uint64_t total) { total_.store(total, std::memory_order_relaxed); }

void Progress::finish() {
  std::lock_guard lock(draw_mutex_);
  if (finished_) return;
  finished_ = true;
  if (enabled_) draw(true);
}

// Called with draw_mutex_ held. The final draw erases the bar, leaving the cursor at the start of
// an empty line for whatever is printed next.
void Progress::draw(bool final_draw) {
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (final_draw) {
    if (terminal_) std::fputs("\r\33[2K", stderr);
    else if (drawn_) std::fprintf(stderr, "%s: done in %s\n", label_.c_str(), format_duration(elapsed).c_str());
    std::fflush(stderr);
    return;
  }
  if (finished_) return;
  const uint64_t done = done_.load(std::memory_order_relaxed);
  const uint64_t total = total_.load(std::memory_order_relaxed);
  const double fraction =
      total > 0 ? std::min(1.0, static_cast<double>(done) / static_cast<double>(total)) : 0.0;
  drawn_ = true;
  const int filled = static_cast<int>(fraction * kBarWidth);
  std::string line = terminal_ ? "\r" + label_ + " [" + std::string(filled, '#') +
                                     std::string(kBarWidth - filled, '.') + "] "
                               : label_ + ": ";
  char percent[8];
  std::snprintf(percent, sizeof(percent), "%3d%%", static_cast<int>(fraction * 100.0));
  line += percent;
  char count[64];
  std::snprintf(count, sizeof(count), " (%llu/%llu)", static_cast<unsigned long long>(done),
                static_cast<unsigned long long>(total));
  if (!terminal_) line += count;
  line += "  " + format_duration(elapsed) + " elapsed";
  if (fraction > 0.0 && fraction < 1.0)
    line += ", ETA " + format_duration(elapsed * (1.0 - fraction) / fraction);
  if (elapsed > 0.0) line += ", " + format_rate(static_cast<double>(done) / elapsed) + " " + unit_ + "/s";
  line += terminal_ ? "\33[K" : "\n";  // erase whatever a longer previous line left behind
  std::fputs(line.c_str(), stderr);
  std::fflush(stderr);
}

}  // namespace gilt::raytrace_core::util
