#include <autodrive/devtools/fake_nano.hpp>

#include <fcntl.h>
#include <poll.h>
#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <stdexcept>

namespace autodrive::devtools {

void PtyPeer::open() {
  close();
  int slave = -1;
  char name[128];
  if (openpty(&master_, &slave, name, nullptr, nullptr) != 0)
    throw std::runtime_error("openpty failed");
  // Raw mode on the slave side so the bytes pass untouched until the component sets its own.
  termios t{};
  tcgetattr(slave, &t);
  cfmakeraw(&t);
  tcsetattr(slave, TCSANOW, &t);
  ::close(slave);  // the component opens it by name
  fcntl(master_, F_SETFL, fcntl(master_, F_GETFL) | O_NONBLOCK);
  ::unlink(link_.c_str());
  if (::symlink(name, link_.c_str()) != 0) throw std::runtime_error("symlink " + link_ + " failed");
}

void PtyPeer::close() {
  if (master_ >= 0) ::close(master_);
  master_ = -1;
  ::unlink(link_.c_str());
}

std::vector<uint8_t> PtyPeer::read(int timeout_ms) {
  std::vector<uint8_t> out;
  if (master_ < 0) return out;
  pollfd p{master_, POLLIN, 0};
  const int r = ::poll(&p, 1, timeout_ms);
  if (r > 0 && !(p.revents & POLLIN)) {
    // Hang-up while nobody has the slave open: nothing to read, wait as asked.
    ::usleep(static_cast<useconds_t>(timeout_ms) * 1000u);
    return out;
  }
  if (r <= 0) return out;
  uint8_t buf[4096];
  for (;;) {
    const ssize_t n = ::read(master_, buf, sizeof buf);
    if (n <= 0) break;
    out.insert(out.end(), buf, buf + n);
  }
  return out;
}

void PtyPeer::write(const std::vector<uint8_t> &bytes) {
  std::size_t done = 0;
  while (master_ >= 0 && done < bytes.size()) {
    const ssize_t n = ::write(master_, bytes.data() + done, bytes.size() - done);
    if (n > 0)
      done += static_cast<std::size_t>(n);
    else if (n < 0 && errno != EAGAIN && errno != EINTR)
      break;
    else {
      pollfd p{master_, POLLOUT, 0};
      ::poll(&p, 1, 10);
    }
  }
}

FakeNano::FakeNano(const std::string &link, uint32_t hash) : pty(link), schema_hash(hash) {
  protocol_parser_init(&parser_);
}

void FakeNano::on_frame(const protocol_frame_t *f, void *ctx) {
  auto *self = static_cast<FakeNano *>(ctx);
  if (f->id == PROTOCOL_ID_HELLO_REQUEST) {
    ++self->hello_requests;
    protocol_hello_t h{1, 2, 3, PROTOCOL_VERSION, self->schema_hash, 0xB1D};
    uint8_t payload[PROTOCOL_LEN_HELLO], frame[PROTOCOL_MAX_FRAME];
    protocol_hello_pack(&h, payload);
    const size_t n = protocol_frame_encode(PROTOCOL_ID_HELLO, self->seq_++, payload,
                                           PROTOCOL_LEN_HELLO, frame, sizeof frame);
    self->pty.write(std::vector<uint8_t>(frame, frame + n));
    ++self->hellos_sent;
  } else if (f->id == PROTOCOL_ID_COMMAND) {
    protocol_command_t c{};
    if (protocol_command_unpack(f->payload, f->len, &c) == 0) self->commands.push_back(c);
  } else if (f->id == PROTOCOL_ID_CONFIG) {
    if (protocol_config_unpack(f->payload, f->len, &self->last_config) == 0) ++self->configs;
  }
}

void FakeNano::pump(int timeout_ms) {
  const std::vector<uint8_t> in = pty.read(timeout_ms);
  if (!in.empty()) protocol_parser_feed(&parser_, in.data(), in.size(), &FakeNano::on_frame, this);
}

void FakeNano::send_state(const protocol_state_t &s) {
  uint8_t payload[PROTOCOL_LEN_STATE], frame[PROTOCOL_MAX_FRAME];
  protocol_state_pack(&s, payload);
  const size_t n = protocol_frame_encode(PROTOCOL_ID_STATE, seq_++, payload, PROTOCOL_LEN_STATE,
                                         frame, sizeof frame);
  pty.write(std::vector<uint8_t>(frame, frame + n));
}

}  // namespace autodrive::devtools
