// The command signer (<autodrive/command_auth.hpp>) against the shared test vectors, and every
// rule of the bridge's command gate (bridge/command_gate.hpp) with explicit times.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <sys/stat.h>
#include <unistd.h>

#include <autodrive/command_auth.hpp>

#include <fstream>

#include <autodrive/nano_bridge/command_gate.hpp>

namespace {

using autodrive::vehicle_command_t;
namespace auth = autodrive::auth;

std::string hex(const uint8_t *p, size_t n) {
  std::string s;
  for (size_t i = 0; i < n; ++i) {
    s += "0123456789abcdef"[p[i] >> 4];
    s += "0123456789abcdef"[p[i] & 15];
  }
  return s;
}

auth::Key key_of(const std::string &h) {
  auth::Key k{};
  for (size_t i = 0; i < k.size(); ++i)
    k[i] = static_cast<uint8_t>(std::stoul(h.substr(2 * i, 2), nullptr, 16));
  return k;
}

TEST(CommandAuth, MatchesTheSharedTestVectors) {
  std::ifstream f(std::string(AUTODRIVE_ROOT) + "/tests/foundation/command_auth_vectors.json");
  ASSERT_TRUE(f) << "test vectors missing";
  const auto doc = nlohmann::json::parse(f);
  ASSERT_GE(doc["vectors"].size(), 3u);
  for (const auto &v : doc["vectors"]) {
    vehicle_command_t c{};
    const auto &j = v["cmd"];
    c.utime = j["utime"];
    c.seq = j["seq"];
    c.throttle = j["throttle"].get<float>();
    c.steering = j["steering"].get<float>();
    c.headlights = j["headlights"].get<int8_t>();
    c.indicators = j["indicators"].get<int8_t>();
    c.engaged = j["engaged"];
    c.source = j["source"];
    c.authority = j["authority"].get<int8_t>();
    c.counter = j["counter"];
    const auto m = auth::canonical_bytes(c, v["vehicle"]);
    EXPECT_EQ(hex(m.data(), m.size()), v["canonical_hex"]);
    const auto mac = auth::mac_of(key_of(v["key"]), m);
    EXPECT_EQ(hex(mac.data(), mac.size()), v["mac_hex"]);
    std::copy(mac.begin(), mac.end(), c.mac);
    EXPECT_EQ(auth::check_mac(key_of(v["key"]), v["vehicle"], c), auth::MacCheck::ok);
    // Any change of a covered field, or another car, breaks it.
    vehicle_command_t d = c;
    d.throttle += 0.001f;
    EXPECT_EQ(auth::check_mac(key_of(v["key"]), v["vehicle"], d), auth::MacCheck::bad_mac);
    EXPECT_EQ(auth::check_mac(key_of(v["key"]), "NIGEL9", c), auth::MacCheck::bad_mac);
  }
}

TEST(CommandAuth, KeyFilesAreCheckedAndNamed) {
  const std::string path = "/tmp/adr-key-test-" + std::to_string(getpid()) + ".key";
  {
    std::ofstream f(path);
    f << std::string(64, 'a') << "\n";
  }
  ::chmod(path.c_str(), 0644);
  try {
    auth::load_key(path);
    ADD_FAILURE() << "a world-readable key was accepted";
  } catch (const autodrive::InputError &e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("group or others"), std::string::npos) << e.what();
  }
  ::chmod(path.c_str(), 0600);
  EXPECT_EQ(auth::load_key(path)[0], 0xaa);
  {
    std::ofstream f(path);
    f << "abc\n";
  }
  EXPECT_THROW(auth::load_key(path), autodrive::InputError);
  ::unlink(path.c_str());
  EXPECT_THROW(auth::load_key(path), autodrive::InputError);
}

// A gate with a 1 s replay window and a 300 ms lease, started long ago; times in us.
struct GateTest : ::testing::Test {
  auth::Key key = key_of(std::string(64, '7'));
  autodrive::bridge::CommandGate gate{key, "NIGEL1", 1000000, 300000, 0};
  auth::Signer autonomy{key, "NIGEL1", "autonomy", auth::kAuthorityMachine};
  auth::Signer policy{key, "NIGEL1", "policy", auth::kAuthorityMachine};
  auth::Signer teleop{key, "NIGEL1", "teleop", auth::kAuthorityPerson};
  int64_t wall0 = 0;
  void SetUp() override {
    vehicle_command_t c{};
    autonomy.sign(c);
    wall0 = c.counter;  // the signers' clock is the wall clock
  }
  vehicle_command_t cmd(auth::Signer &s, bool engaged, float throttle = 0.3f) {
    vehicle_command_t c{};
    c.throttle = throttle;
    c.engaged = engaged;
    s.sign(c);
    return c;
  }
  autodrive::bridge::Drop admit(const vehicle_command_t &c, int64_t mono_us) {
    return gate.admit(c, mono_us, c.counter).drop;  // wall clock == the signer's, here
  }
};

TEST_F(GateTest, UnsignedAndBadMacDropped) {
  vehicle_command_t c{};
  c.engaged = true;
  EXPECT_EQ(admit(c, 0), autodrive::bridge::Drop::unsigned_cmd);
  c = cmd(autonomy, true);
  c.mac[3] ^= 0x10;
  EXPECT_EQ(admit(c, 0), autodrive::bridge::Drop::bad_mac);
  EXPECT_EQ(gate.counters().dropped_unsigned, 1);
  EXPECT_EQ(gate.counters().dropped_bad_mac, 1);
  EXPECT_EQ(gate.holder(), "");
}

TEST_F(GateTest, ReplaysAndStaleCountersDropped) {
  const auto c = cmd(autonomy, true);
  EXPECT_EQ(admit(c, 0), autodrive::bridge::Drop::none);
  EXPECT_EQ(admit(c, 1000), autodrive::bridge::Drop::replay);  // the same counter again
  const auto later = cmd(autonomy, true);
  EXPECT_EQ(gate.admit(later, 2000, later.counter + 2000000).drop,
            autodrive::bridge::Drop::replay);  // old
  EXPECT_EQ(gate.admit(later, 2000, later.counter - 2000000).drop,
            autodrive::bridge::Drop::replay);  // future
  EXPECT_EQ(gate.counters().dropped_replay, 3);
}

// A bridge that restarts knows no source's last counter: a replay of a command signed before it
// started, still inside the window, must not pass as new (nor take the free lease).
TEST_F(GateTest, ReplayOfACommandSignedBeforeARestartDropped) {
  const auto before = cmd(autonomy, true);  // recorded by an attacker ...
  EXPECT_EQ(admit(before, 0), autodrive::bridge::Drop::none);
  // the bridge restarts right after it was signed
  autodrive::bridge::CommandGate restarted{key, "NIGEL1", 1000000, 300000, before.counter};
  const int64_t wall = before.counter + 200000;  // ... and the attacker replays it 0.2 s later
  EXPECT_EQ(restarted.admit(before, 0, wall).drop, autodrive::bridge::Drop::replay);
  EXPECT_EQ(restarted.holder(), "");
  // the source's next command (its counter only grows) passes and takes the lease
  const auto fresh = cmd(autonomy, true);
  EXPECT_EQ(restarted.admit(fresh, 1000, fresh.counter).drop, autodrive::bridge::Drop::none);
  EXPECT_EQ(restarted.holder(), "autonomy");
  EXPECT_EQ(restarted.counters().dropped_replay, 1);
}

TEST_F(GateTest, FirstEngagedSourceTakesAFreeLeaseIdleOnesDoNot) {
  EXPECT_EQ(admit(cmd(teleop, false), 0),
            autodrive::bridge::Drop::idle);  // an idle teleop asks for nothing
  EXPECT_EQ(gate.holder(), "");
  EXPECT_EQ(admit(cmd(autonomy, true), 0), autodrive::bridge::Drop::none);
  EXPECT_EQ(gate.holder(), "autonomy");
  // Another machine may not take it while the lease lives ...
  EXPECT_EQ(admit(cmd(policy, true), 100000), autodrive::bridge::Drop::not_holder);
  // ... the holder renews it with every command, engaged or not ...
  EXPECT_EQ(admit(cmd(autonomy, false), 250000), autodrive::bridge::Drop::none);
  EXPECT_EQ(admit(cmd(policy, true), 500000), autodrive::bridge::Drop::not_holder);
  // ... and once it lapses the next engaged source takes it.
  EXPECT_TRUE(gate.expire(551000));
  EXPECT_EQ(gate.holder(), "");
  EXPECT_EQ(admit(cmd(policy, true), 552000), autodrive::bridge::Drop::none);
  EXPECT_EQ(gate.holder(), "policy");
  EXPECT_EQ(gate.counters().holder_changes, 3);
}

TEST_F(GateTest, PersonTakesFromMachineMachineNeverFromPerson) {
  EXPECT_EQ(admit(cmd(autonomy, true), 0), autodrive::bridge::Drop::none);
  EXPECT_EQ(admit(cmd(teleop, false), 10000), autodrive::bridge::Drop::idle);  // dead-man not held
  EXPECT_EQ(gate.holder(), "autonomy");
  const auto v = gate.admit(cmd(teleop, true, 0.5f), 20000, wall0);
  EXPECT_EQ(v.drop, autodrive::bridge::Drop::none);
  EXPECT_TRUE(v.holder_changed);
  EXPECT_EQ(gate.holder(), "teleop");
  EXPECT_EQ(gate.holder_authority(), auth::kAuthorityPerson);
  // Dead-man released: the person still holds control; the autonomy cannot take it.
  for (int64_t t = 30000; t < 2000000; t += 100000) {
    EXPECT_EQ(admit(cmd(teleop, false), t), autodrive::bridge::Drop::none);
    EXPECT_EQ(admit(cmd(autonomy, true), t + 50000), autodrive::bridge::Drop::not_holder);
  }
  EXPECT_EQ(gate.holder(), "teleop");
}

}  // namespace
