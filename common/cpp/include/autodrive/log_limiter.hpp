// A rate-limited log for events an outsider can repeat at will (a malformed message, a forged
// health packet, garbage on a serial link): per source (a channel or device name) at most
// max_lines lines per period, then one summary line with the count, e.g.
//   "dropped 2,431 malformed messages on NIGEL_STATE in the last 10 s (2,436 in total)".
// A flood then costs at most max_lines + 1 lines per period and source instead of one line per
// message, and nothing is hidden: every event is counted. Thread-safe; header-only, on spdlog.
#pragma once

#include <spdlog/spdlog.h>

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>

namespace autodrive {

// 2431 -> "2,431": the counts people read in a log.
inline std::string with_thousands(uint64_t n) {
  std::string digits = std::to_string(n), out;
  for (size_t i = 0; i < digits.size(); ++i) {
    if (i && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return out;
}

struct LogLimits {
  int max_lines = 5;                        // lines per source and period
  std::chrono::milliseconds period{10000};  // [ms]
  spdlog::level::level_enum level = spdlog::level::warn;
};

class LogLimiter {
 public:
  using Clock = std::chrono::steady_clock;
  using Options = LogLimits;
  // what: the plural noun of the event ("malformed messages"); logger: spdlog's default if null.
  explicit LogLimiter(std::string what, Options options = Options(),
                      std::shared_ptr<spdlog::logger> logger = nullptr)
      : what_(std::move(what)), options_(options), logger_(std::move(logger)) {}

  // One event on `source`; logs "<source>: <message>" while the source is within its budget,
  // else only counts it. Returns true if the line was logged.
  bool event(const std::string &source, const std::string &message,
             Clock::time_point now = Clock::now()) {
    std::lock_guard<std::mutex> lock(mutex_);
    Source &s = sources_[source];
    if (!s.started) {
      s.started = true;
      s.period_start = now;
    }
    roll(source, s, now);
    ++s.total;
    if (s.logged_in_period < options_.max_lines) {
      ++s.logged_in_period;
      write(source + ": " + message);
      return true;
    }
    ++s.dropped_in_period;
    return false;
  }
  // Writes the summary of every source whose period is over; call it now and then (e.g. on a
  // receive timeout) so that the summary of a flood that stopped is not held back.
  void flush(Clock::time_point now = Clock::now()) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto &kv : sources_) roll(kv.first, kv.second, now);
  }
  uint64_t total(const std::string &source) const {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = sources_.find(source);
    return it == sources_.end() ? 0 : it->second.total;
  }
  uint64_t total() const {
    std::lock_guard<std::mutex> lock(mutex_);
    uint64_t n = 0;
    for (const auto &kv : sources_) n += kv.second.total;
    return n;
  }
  const std::string &what() const { return what_; }

 private:
  struct Source {
    bool started = false;
    Clock::time_point period_start;
    int logged_in_period = 0;
    uint64_t dropped_in_period = 0;
    uint64_t total = 0;
  };
  void roll(const std::string &name, Source &s, Clock::time_point now) {
    if (now - s.period_start < options_.period) return;
    if (s.dropped_in_period) {
      const double elapsed_s = std::chrono::duration<double>(now - s.period_start).count();
      write(fmt::format("dropped {} {} on {} in the last {:.0f} s ({} in total)",
                        with_thousands(s.dropped_in_period), what_, name, elapsed_s,
                        with_thousands(s.total)));
    }
    s.period_start = now;
    s.logged_in_period = 0;
    s.dropped_in_period = 0;
  }
  void write(const std::string &line) const {
    spdlog::logger &l = logger_ ? *logger_ : *spdlog::default_logger_raw();
    l.log(options_.level, "{}", line);
  }
  std::string what_;
  Options options_;
  std::shared_ptr<spdlog::logger> logger_;
  mutable std::mutex mutex_;
  std::map<std::string, Source> sources_;
};

}  // namespace autodrive
