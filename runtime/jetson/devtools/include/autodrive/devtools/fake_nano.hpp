// Peers on real pseudo-terminals for the runtime's tests and runtime-link-bench: the peer holds
// the master side, the component under test opens the slave through a symlink, exactly as it
// opens the simulator's ptys.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "protocol.h"

namespace autodrive::devtools {

// A pty whose slave is reachable at `link` (a symlink). close() makes the device disappear.
class PtyPeer {
 public:
  explicit PtyPeer(std::string link) : link_(std::move(link)) {}
  ~PtyPeer() { close(); }
  void open();   // new pty + symlink (replaces a stale link)
  void close();  // closes the master and removes the link: the device is gone
  bool is_open() const { return master_ >= 0; }
  // Reads what the component wrote, waiting up to timeout_ms for the first byte.
  std::vector<uint8_t> read(int timeout_ms);
  void write(const std::vector<uint8_t> &bytes);
  const std::string &link() const { return link_; }

 private:
  std::string link_;
  int master_ = -1;
};

// A Nano made of the shared proto codec: answers HELLO_REQUEST with a HELLO carrying
// `schema_hash`, records COMMAND/CONFIG frames, sends STATE frames on request.
class FakeNano {
 public:
  explicit FakeNano(const std::string &link, uint32_t schema_hash = protocol_schema_hash());
  void open() {
    pty.open();
    protocol_parser_init(&parser_);
  }
  void close() { pty.close(); }
  // Reads and handles what arrived (up to timeout_ms for the first byte).
  void pump(int timeout_ms);
  void send_state(const protocol_state_t &s);

  PtyPeer pty;
  uint32_t schema_hash;
  int hello_requests = 0;
  int hellos_sent = 0;
  int configs = 0;
  std::vector<protocol_command_t> commands;
  protocol_config_t last_config{};

 private:
  static void on_frame(const protocol_frame_t *f, void *ctx);
  protocol_parser_t parser_{};
  uint8_t seq_ = 0;
};

}  // namespace autodrive::devtools
