// Mission state machine transitions.
#include <gtest/gtest.h>

#include <autodrive/autonomy/mission.hpp>

using namespace autodrive::autonomy;

TEST(Mission, HappyPathVisitsEveryStateInOrder) {
  Mission m(MissionConfig{}, 0.0);
  EXPECT_EQ(m.state(), MissionState::kMapping);
  EXPECT_FALSE(m.localised(1.0));  // not applicable while mapping
  EXPECT_EQ(m.state(), MissionState::kMapping);
  EXPECT_TRUE(m.mapping_done(1.0));
  EXPECT_EQ(m.state(), MissionState::kSaving);
  EXPECT_TRUE(m.saved(true, "ok", 1.1));
  EXPECT_EQ(m.state(), MissionState::kLocalising);
  EXPECT_TRUE(m.localised(2.0));
  EXPECT_EQ(m.state(), MissionState::kPlanning);
  EXPECT_TRUE(m.planned(true, "ok", 2.1));
  EXPECT_EQ(m.state(), MissionState::kDriving);
  EXPECT_TRUE(m.arrived(true, "in slot", 9.0));
  EXPECT_EQ(m.state(), MissionState::kParked);
  EXPECT_TRUE(m.finished());
  EXPECT_FALSE(m.fail("late", 10.0));  // terminal
  EXPECT_EQ(m.history().size(), 5u);
  EXPECT_EQ(static_cast<int>(MissionState::kParked), 5);  // mission_status_t.PARKED
}

TEST(Mission, StartsLocalisingWithAGivenMap) {
  MissionConfig c;
  c.start_with_map = true;
  Mission m(c);
  EXPECT_EQ(m.state(), MissionState::kLocalising);
}

TEST(Mission, BlockedPathReplansUntilTheLimit) {
  MissionConfig c;
  c.start_with_map = true;
  c.max_replans = 2;
  Mission m(c);
  m.localised(0);
  m.planned(true, "", 0);
  EXPECT_TRUE(m.blocked("box", 1));
  EXPECT_EQ(m.state(), MissionState::kPlanning);
  m.planned(true, "", 1);
  EXPECT_TRUE(m.arrived(false, "off by 5 cm", 2));
  EXPECT_EQ(m.state(), MissionState::kPlanning);
  m.planned(true, "", 2);
  EXPECT_TRUE(m.blocked("box", 3));
  EXPECT_EQ(m.state(), MissionState::kFailed);
  EXPECT_EQ(m.replans(), 3);
}

TEST(Mission, FailuresAndTimeouts) {
  {
    Mission m(MissionConfig{});
    m.mapping_done(0);
    m.saved(false, "disk full", 0);
    EXPECT_EQ(m.state(), MissionState::kFailed);
    EXPECT_EQ(m.detail(), "disk full");
  }
  {
    MissionConfig c;
    c.start_with_map = true;
    Mission m(c);
    m.localised(0);
    EXPECT_TRUE(m.planned(false, "no path", 0.5));
    EXPECT_EQ(m.state(), MissionState::kFailed);
  }
  {
    MissionConfig c;
    c.timeout_mapping_s = 5;
    Mission m(c, 100.0);
    m.tick(104.9);
    EXPECT_EQ(m.state(), MissionState::kMapping);
    m.tick(105.1);
    EXPECT_EQ(m.state(), MissionState::kFailed);
    EXPECT_NE(m.detail().find("timeout"), std::string::npos);
  }
  {
    Mission m(MissionConfig{});
    EXPECT_FALSE(m.blocked("x", 0));  // not driving
    EXPECT_FALSE(m.arrived(true, "x", 0));
    EXPECT_TRUE(m.fail("estop", 0));
    EXPECT_EQ(m.state(), MissionState::kFailed);
  }
}
