// A raw serial device (termios, 8N1, no flow control, non-blocking). Works on a USB-serial
// adapter, a real UART and a pseudo-terminal alike (a pty accepts any baud rate).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace autodrive::serial {

class SerialPort {
 public:
  SerialPort() = default;
  ~SerialPort() { close(); }
  SerialPort(const SerialPort &) = delete;
  SerialPort &operator=(const SerialPort &) = delete;

  // Opens and configures `path` at `baud` [bit/s]. Returns "" on success, else why it failed
  // (naming the device), e.g. "/dev/ttyUSB0: No such file or directory".
  std::string open(const std::string &path, int baud);
  void close();
  bool is_open() const { return fd_ >= 0; }
  int fd() const { return fd_; }

  // Reads what is available (never blocks). Returns bytes read, 0 if none, -1 if the device
  // is gone (hang-up, EIO, removed); `error()` then says why.
  long read_some(uint8_t *buf, std::size_t cap);
  // Writes all bytes, waiting up to ~50 ms for room. Returns 1 when written, 0 when the
  // output queue stayed full (the bytes not written are dropped), -1 if the device is gone.
  int write_all(const uint8_t *data, std::size_t n);
  const std::string &error() const { return error_; }

 private:
  int fd_ = -1;
  std::string path_;
  std::string error_;
};

}  // namespace autodrive::serial
