// Probe finding: every malformed LCM message gave one log line (LCM prints one per message);
// autodrive_lcm::subscribe decodes itself, counts per channel and logs at a limited rate.
#include <autodrive/vehicle_state_t.hpp>
#include <autodrive_lcm/subscribe.hpp>
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <vector>

namespace {
struct Sink {
  int received = 0;
  void on_state(const autodrive::vehicle_state_t *) { ++received; }
};
}  // namespace

TEST(MalformedLcm, CountedPerChannelAndNeverHandedToTheHandler) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  Sink sink;
  autodrive_lcm::subscribe<autodrive::vehicle_state_t, Sink, &Sink::on_state>(lcm, "T_MAL_STATE",
                                                                              &sink);
  const uint64_t before = autodrive_lcm::malformed_log().total("T_MAL_STATE");
  std::vector<uint8_t> garbage(37, 0xA5);
  for (int i = 0; i < 50; ++i) {
    lcm.publish("T_MAL_STATE", garbage.data(), static_cast<unsigned>(garbage.size()));
    ASSERT_GT(lcm.handleTimeout(1000), 0);
  }
  // A good message with trailing bytes is not that message either.
  autodrive::vehicle_state_t good{};
  std::vector<uint8_t> buf(static_cast<size_t>(good.getEncodedSize()) + 3);
  ASSERT_EQ(good.encode(buf.data(), 0, good.getEncodedSize()), good.getEncodedSize());
  lcm.publish("T_MAL_STATE", buf.data(), static_cast<unsigned>(buf.size()));
  ASSERT_GT(lcm.handleTimeout(1000), 0);
  EXPECT_EQ(autodrive_lcm::malformed_log().total("T_MAL_STATE") - before, 51u);
  EXPECT_EQ(sink.received, 0);
  lcm.publish("T_MAL_STATE", &good);
  ASSERT_GT(lcm.handleTimeout(1000), 0);
  EXPECT_EQ(sink.received, 1);
}
