// AUTODRIVE_INSTANCE (<autodrive/instance.hpp>): instance N moves the default bus and the
// simulator's ptys, leaves other ports alone, refuses a bad number; the runtime's config reads it.
#include <autodrive/core/config.hpp>
#include <autodrive/instance.hpp>
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

namespace {

struct InstanceEnv : ::testing::Test {
  void TearDown() override { unsetenv(AUTODRIVE_INSTANCE_VARIABLE); }
};

TEST_F(InstanceEnv, UnsetKeepsTheDefaults) {
  unsetenv(AUTODRIVE_INSTANCE_VARIABLE);
  EXPECT_EQ(autodrive::instance().number(), 0);
  EXPECT_EQ(autodrive::instance_lcm_url(AUTODRIVE_LCM_URL_DEFAULT), AUTODRIVE_LCM_URL_DEFAULT);
}

TEST_F(InstanceEnv, MovesTheDefaultPortOnly) {
  const autodrive::Instance two(2);
  const int moved = autodrive::Instance::default_lcm_port() + 2 * AUTODRIVE_INSTANCE_PORT_STEP;
  EXPECT_EQ(two.lcm_url("udpm://239.255.76.67:7667?ttl=0"),
            "udpm://239.255.76.67:" + std::to_string(moved) + "?ttl=0");
  EXPECT_EQ(two.lcm_url("udpm://239.255.76.67:7667"),
            "udpm://239.255.76.67:" + std::to_string(moved));
  EXPECT_EQ(two.lcm_url(""), two.lcm_url(AUTODRIVE_LCM_URL_DEFAULT));  // LCM's own default
  EXPECT_EQ(two.lcm_url("udpm://239.255.76.67:7701?ttl=0"), "udpm://239.255.76.67:7701?ttl=0");
  EXPECT_EQ(two.lcm_url("memq://"), "memq://");
  EXPECT_EQ(two.lcm_url(two.lcm_url(AUTODRIVE_LCM_URL_DEFAULT)),
            two.lcm_url(AUTODRIVE_LCM_URL_DEFAULT));  // moving twice changes nothing
  EXPECT_EQ(two.sim_path(AUTODRIVE_SIM_RUN_DIR_DEFAULT "/nigel1-nano"),
            AUTODRIVE_SIM_RUN_DIR_DEFAULT "-2/nigel1-nano");
  EXPECT_EQ(two.sim_path("/dev/nigel-nano"), "/dev/nigel-nano");
}

TEST_F(InstanceEnv, BadNumberNamesTheVariable) {
  for (const char *bad : {"x", "-1", "999", "1.5"}) {
    setenv(AUTODRIVE_INSTANCE_VARIABLE, bad, 1);
    try {
      autodrive::instance();
      ADD_FAILURE() << bad << " accepted";
    } catch (const autodrive::InstanceError &e) {
      EXPECT_NE(std::string(e.what()).find(AUTODRIVE_INSTANCE_VARIABLE), std::string::npos);
    }
  }
}

TEST_F(InstanceEnv, RuntimeConfigFollowsTheInstance) {
  const std::string yaml =
      "lcm_url: \"udpm://239.255.76.67:7667?ttl=0\"\nclock: wall\nvehicle:\n  name: NIGEL1\n";
  setenv(AUTODRIVE_INSTANCE_VARIABLE, "3", 1);
  const auto c = autodrive::config::parse(yaml, "instance.yaml");
  EXPECT_EQ(c.lcm_url, autodrive::Instance(3).lcm_url(AUTODRIVE_LCM_URL_DEFAULT));
  setenv(AUTODRIVE_INSTANCE_VARIABLE, "nope", 1);
  EXPECT_THROW(autodrive::config::parse(yaml, "instance.yaml"), autodrive::config::Error);
}

}  // namespace
