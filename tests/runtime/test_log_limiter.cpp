// The rate-limited log (<autodrive/log_limiter.hpp>): a flood of events costs at most max_lines
// lines per period and source plus one summary line that counts what was dropped.
#include <autodrive/log_limiter.hpp>
#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>

#include <sstream>
#include <string>
#include <vector>

namespace {

using autodrive::LogLimiter;
using std::chrono::milliseconds;

struct Captured {
  std::ostringstream text;
  std::shared_ptr<spdlog::logger> logger;
  Captured() {
    auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(text);
    sink->set_pattern("%v");
    logger = std::make_shared<spdlog::logger>("captured", sink);
  }
  std::vector<std::string> lines() const {
    std::vector<std::string> out;
    std::istringstream in(text.str());
    for (std::string l; std::getline(in, l);) out.push_back(l);
    return out;
  }
};

TEST(LogLimiter, ThousandsSeparators) {
  EXPECT_EQ(autodrive::with_thousands(0), "0");
  EXPECT_EQ(autodrive::with_thousands(999), "999");
  EXPECT_EQ(autodrive::with_thousands(2431), "2,431");
  EXPECT_EQ(autodrive::with_thousands(1234567), "1,234,567");
}

TEST(LogLimiter, FloodGivesMaxLinesThenOneSummaryWithTheCount) {
  Captured c;
  LogLimiter log("malformed messages", {3, milliseconds(10000), spdlog::level::warn}, c.logger);
  const auto t0 = LogLimiter::Clock::time_point{};
  int logged = 0;
  for (int i = 0; i < 2434; ++i)
    logged += log.event("NIGEL_STATE", "bad length", t0 + milliseconds(i));
  EXPECT_EQ(logged, 3);
  ASSERT_EQ(c.lines().size(), 3u);
  EXPECT_EQ(c.lines()[0], "NIGEL_STATE: bad length");
  log.flush(t0 + milliseconds(9999));  // period not over: nothing yet
  EXPECT_EQ(c.lines().size(), 3u);
  log.flush(t0 + milliseconds(10000));
  ASSERT_EQ(c.lines().size(), 4u);
  EXPECT_EQ(c.lines()[3],
            "dropped 2,431 malformed messages on NIGEL_STATE in the last 10 s "
            "(2,434 in total)");
  EXPECT_EQ(log.total("NIGEL_STATE"), 2434u);
  // A new period has a fresh budget; a quiet period writes no summary.
  EXPECT_TRUE(log.event("NIGEL_STATE", "again", t0 + milliseconds(10001)));
  log.flush(t0 + milliseconds(30000));
  EXPECT_EQ(c.lines().size(), 5u);
}

TEST(LogLimiter, SourcesHaveTheirOwnBudget) {
  Captured c;
  LogLimiter log("malformed messages", {1, milliseconds(1000), spdlog::level::warn}, c.logger);
  const auto t0 = LogLimiter::Clock::time_point{};
  for (int i = 0; i < 10; ++i) {
    log.event("A", "x", t0);
    log.event("B", "y", t0);
  }
  EXPECT_EQ(c.lines(), (std::vector<std::string>{"A: x", "B: y"}));
  // The summary is written by the next event of the source as well as by flush().
  log.event("A", "x", t0 + milliseconds(1500));
  ASSERT_EQ(c.lines().size(), 4u);
  EXPECT_EQ(c.lines()[2], "dropped 9 malformed messages on A in the last 2 s (10 in total)");
  EXPECT_EQ(c.lines()[3], "A: x");
  EXPECT_EQ(log.total(), 21u);
}

TEST(LogLimiter, LinesPerSecondStayBoundedUnderAFlood) {
  Captured c;
  LogLimiter log("forged packets", {5, milliseconds(10000), spdlog::level::warn}, c.logger);
  const auto t0 = LogLimiter::Clock::time_point{};
  // 2,600 events/s for 60 s on one source.
  for (int i = 0; i < 2600 * 60; ++i)
    log.event("/dev/ttyUSB0", "bad", t0 + std::chrono::microseconds(i * 385));
  log.flush(t0 + milliseconds(70000));
  const double lines_per_s = static_cast<double>(c.lines().size()) / 60.0;
  EXPECT_LE(lines_per_s, 0.7);  // (5 + 1) lines per 10 s
  EXPECT_GE(c.lines().size(), 6u * 6u);
}

}  // namespace
