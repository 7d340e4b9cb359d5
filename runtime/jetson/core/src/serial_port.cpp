#include <autodrive/core/serial_port.hpp>

#include <asm/termbits.h>  // termios2 / BOTHER: any baud rate, not only the Bxxx constants
#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <unistd.h>

namespace autodrive::serial {

std::string SerialPort::open(const std::string &path, int baud) {
  close();
  path_ = path;
  const int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0 && errno == ENOENT && path.rfind("/dev/nigel-", 0) == 0)
    return path +
           ": no such device: unplugged, or the udev rules that make this name are not "
           "installed (tools/udev/99-autodrive-nigel.rules, docs/guides/jetson.md)";
  if (fd < 0) return path + ": " + std::strerror(errno);
  struct termios2 tio {};
  if (ioctl(fd, TCGETS2, &tio) != 0) {
    const std::string why = path + ": not a serial device (" + std::strerror(errno) + ")";
    ::close(fd);
    return why;
  }
  // Raw 8N1, no flow control, no echo, no line editing: every byte goes through untouched.
  tio.c_iflag &= ~static_cast<tcflag_t>(IGNBRK | BRKINT | PARMRK | ISTRIP | INLCR | IGNCR | ICRNL |
                                        IXON | IXOFF | IXANY);
  tio.c_oflag &= ~static_cast<tcflag_t>(OPOST);
  tio.c_lflag &= ~static_cast<tcflag_t>(ECHO | ECHONL | ICANON | ISIG | IEXTEN);
  tio.c_cflag &= ~static_cast<tcflag_t>(CSIZE | PARENB | CSTOPB | CRTSCTS | CBAUD);
  tio.c_cflag |= CS8 | CLOCAL | CREAD | BOTHER;
  tio.c_ispeed = static_cast<speed_t>(baud);
  tio.c_ospeed = static_cast<speed_t>(baud);
  tio.c_cc[VMIN] = 0;
  tio.c_cc[VTIME] = 0;
  if (ioctl(fd, TCSETS2, &tio) != 0) {
    const std::string why = path + ": cannot set " + std::to_string(baud) + " baud raw mode (" +
                            std::strerror(errno) + ")";
    ::close(fd);
    return why;
  }
  ioctl(fd, TCFLSH, TCIOFLUSH);  // drop bytes queued before we owned the port
  fd_ = fd;
  error_.clear();
  return "";
}

void SerialPort::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

long SerialPort::read_some(uint8_t *buf, std::size_t cap) {
  if (fd_ < 0) return -1;
  const ssize_t n = ::read(fd_, buf, cap);
  if (n > 0) return static_cast<long>(n);
  if (n < 0 && (errno == EAGAIN || errno == EINTR)) return 0;
  // A tty read of 0 with VMIN=0 means no data; a hang-up shows up in poll() (POLLHUP) and as
  // EIO here. Treat 0 as "nothing" and let the caller check POLLHUP.
  if (n == 0) return 0;
  error_ = path_ + ": " + std::strerror(errno);
  return -1;
}

int SerialPort::write_all(const uint8_t *data, std::size_t n) {
  if (fd_ < 0) return -1;
  std::size_t done = 0;
  int waits = 0;
  while (done < n) {
    const ssize_t w = ::write(fd_, data + done, n - done);
    if (w > 0) {
      done += static_cast<std::size_t>(w);
      continue;
    }
    if (w < 0 && errno == EINTR) continue;
    if (w < 0 && errno == EAGAIN) {
      if (waits >= 5) {
        error_ = path_ + ": output queue full, bytes dropped";
        return 0;
      }
      // Output queue full (a slow UART or a pty nobody reads): wait a little for room.
      struct pollfd p {
        fd_, POLLOUT, 0
      };
      ::poll(&p, 1, 10);
      ++waits;
      continue;
    }
    error_ = path_ + ": write failed (" + (w < 0 ? std::strerror(errno) : "no progress") + ")";
    return -1;
  }
  return 1;
}

}  // namespace autodrive::serial
