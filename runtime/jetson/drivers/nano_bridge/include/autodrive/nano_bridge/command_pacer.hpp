// When a COMMAND frame may go to the Nano. A fresh command goes at once while the token bucket
// has a token (burst_frames deep, refilled at rate_hz); a flood on LCM is capped at rate_hz
// frames per second, its newest command held until the next token. The heartbeat (the last
// command again, or a disengaged frame once it is stale) goes only when no frame went out for
// a heartbeat period, so the Nano's failsafe sees a steady stream while the source is quiet.
// Every frame, heartbeat included, takes a token: whatever arrives, frames in any interval of
// T us number at most burst_frames + T * rate_hz / 1e6. No I/O and no clock of its own: the
// caller passes the time (monotonic, or the sim clock in HIL), so the unit tests drive it.
#pragma once

#include <cstdint>

namespace autodrive::bridge {

class CommandPacer {
 public:
  // burst_frames >= 1; rate_hz >= the heartbeat rate (a heartbeat always finds a token).
  CommandPacer(int burst_frames, double rate_hz, int64_t heartbeat_period_us);

  // The link came up at now_us: a full bucket, and the first heartbeat due at once.
  void restart(int64_t now_us);
  // A fresh command arrived: true when it goes now (a token taken), false when it is held.
  bool command(int64_t now_us);
  // The frame due at now_us, if any: a held command once a token is back, else the heartbeat
  // after a period without frames. True when a frame goes now (a token taken).
  bool due(int64_t now_us);
  // The earliest time [us] at which due() may say true (for the caller's poll timeout).
  int64_t next_due_us() const;

  bool holding() const { return held_; }
  int64_t token_us() const { return token_us_; }  // refill time of one token [us]

 private:
  void refill(int64_t now_us);
  bool take(int64_t now_us);

  int64_t token_us_;      // [us per token]
  int64_t capacity_us_;   // burst_frames * token_us_ [us of credit]
  int64_t heartbeat_us_;  // [us]
  int64_t credit_us_ = 0;
  int64_t refilled_at_us_ = 0;
  int64_t last_frame_us_ = 0;
  bool held_ = false;  // a command waits for a token
};

}  // namespace autodrive::bridge
