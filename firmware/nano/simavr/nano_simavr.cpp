// nano-simavr: runs the real Nigel Nano firmware ELF in simavr, paced to the wall clock, with
// its UART0 on a pseudo-terminal (the "unchanged runtime" connects to it like to
// /dev/ttyUSB0). Optional constant encoder edges and a log of actuator register changes.
#include <fcntl.h>
#include <sys/stat.h>
#include <signal.h>
#include <termios.h>
#include <time.h>
#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "sil_board.h"

namespace {

volatile sig_atomic_t g_stop = 0;
void on_signal(int) {
  g_stop = 1;
}

void usage(FILE *out) {
  std::fprintf(
      out,
      "usage: nano-simavr [options]\n"
      "Runs the Nigel Nano firmware ELF in simavr (ATmega328P, 16 MHz) paced to the wall clock,\n"
      "with UART0 (500000 baud) on a pseudo-terminal.\n"
      "  --elf PATH          firmware ELF (default: <bin>/../nano_avr/nigel_nano.elf)\n"
      "  --bootloader HEX    start as a Nano being flashed: application flash erased, this\n"
      "                      bootloader (e.g. the Nano's ATmegaBOOT) run from reset once an\n"
      "                      uploader configures the pty (the DTR reset of an upload); the\n"
      "                      ELF only names symbols. Upload: avrdude -c arduino -b 57600\n"
      "  --pty PATH          symlink to the pty (default /tmp/nano-simavr/nano)\n"
      "  --encoder-hz N      encoder A edges per second on both wheels, forward (default 0)\n"
      "  --pwm-log FILE      log servo/motor register changes: t_sim_us t_mono_us servo_us\n"
      "                      motor_duty reverse brake (one line per change)\n"
      "  --no-imu            no MPU-9250 on the I2C bus\n"
      "  --speed X           simulated seconds per wall second (default 1; 0 = unpaced)\n"
      "  --duration-s S      stop after S simulated seconds (default 0 = until SIGINT/SIGTERM)\n"
      "  -h, --help          this help\n");
}

uint64_t mono_us() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<uint64_t>(ts.tv_sec) * 1000000u + static_cast<uint64_t>(ts.tv_nsec) / 1000u;
}

std::string default_elf(const char *argv0) {
  char exe[4096];
  ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
  std::string dir = ".";
  if (n > 0) {
    exe[n] = 0;
    dir = exe;
    dir = dir.substr(0, dir.rfind('/'));
  } else if (std::strchr(argv0, '/') != nullptr) {
    dir = std::string(argv0).substr(0, std::string(argv0).rfind('/'));
  }
  return dir + "/../nano_avr/nigel_nano.elf";
}

double parse_number(const char *opt, const char *v, double lo, double hi) {
  char *end = nullptr;
  errno = 0;
  double x = std::strtod(v, &end);
  if (errno != 0 || end == v || *end != 0 || x < lo || x > hi) {
    std::fprintf(stderr, "nano-simavr: %s '%s': expected a number in [%g, %g]\n", opt, v, lo, hi);
    std::exit(2);
  }
  return x;
}

// Opens a raw pty; returns the master fd and keeps a slave fd open (so that the master never
// sees EIO while no client is connected).
int open_pty(std::string *slave_name, int *slave_fd) {
  int m = posix_openpt(O_RDWR | O_NOCTTY);
  if (m < 0 || grantpt(m) != 0 || unlockpt(m) != 0) return -1;
  *slave_name = ptsname(m);
  *slave_fd = open(slave_name->c_str(), O_RDWR | O_NOCTTY);
  if (*slave_fd < 0) return -1;
  termios t{};
  tcgetattr(*slave_fd, &t);
  cfmakeraw(&t);  // no echo, no line discipline: bytes pass through untouched
  tcsetattr(*slave_fd, TCSANOW, &t);
  fcntl(m, F_SETFL, fcntl(m, F_GETFL) | O_NONBLOCK);
  return m;
}

}  // namespace

int main(int argc, char **argv) {
  std::string elf = default_elf(argv[0]);
  std::string pty_link = "/tmp/nano-simavr/nano";
  std::string pwm_log, bootloader;
  double encoder_hz = 0, speed = 1, duration_s = 0;
  bool imu = true;
  for (int i = 1; i < argc; i++) {
    std::string a = argv[i];
    auto value = [&](const char *name) -> const char * {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "nano-simavr: %s needs a value (see --help)\n", name);
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "-h" || a == "--help") {
      usage(stdout);
      return 0;
    } else if (a == "--elf") {
      elf = value("--elf");
    } else if (a == "--bootloader") {
      bootloader = value("--bootloader");
    } else if (a == "--pty") {
      pty_link = value("--pty");
    } else if (a == "--encoder-hz") {
      encoder_hz = parse_number("--encoder-hz", value("--encoder-hz"), 0, 1e6);
    } else if (a == "--pwm-log") {
      pwm_log = value("--pwm-log");
    } else if (a == "--no-imu") {
      imu = false;
    } else if (a == "--speed") {
      speed = parse_number("--speed", value("--speed"), 0, 1000);
    } else if (a == "--duration-s") {
      duration_s = parse_number("--duration-s", value("--duration-s"), 0, 1e7);
    } else {
      std::fprintf(stderr, "nano-simavr: unknown option '%s' (see --help)\n", a.c_str());
      return 2;
    }
  }
  if (!bootloader.empty() && access(bootloader.c_str(), R_OK) != 0) {
    std::fprintf(stderr, "nano-simavr: --bootloader '%s': %s\n", bootloader.c_str(),
                 std::strerror(errno));
    return 1;
  }
  if (access(elf.c_str(), R_OK) != 0) {
    std::fprintf(stderr, "nano-simavr: firmware ELF '%s': %s\n", elf.c_str(), std::strerror(errno));
    return 1;
  }
  FILE *log = nullptr;
  if (!pwm_log.empty()) {
    log = std::fopen(pwm_log.c_str(), "w");
    if (log == nullptr) {
      std::fprintf(stderr, "nano-simavr: --pwm-log '%s': %s\n", pwm_log.c_str(),
                   std::strerror(errno));
      return 1;
    }
    std::fprintf(log, "# t_sim_us t_mono_us servo_us motor_duty reverse brake\n");
  }

  std::string slave;
  int slave_fd = -1;
  const int master = open_pty(&slave, &slave_fd);
  if (master < 0) {
    std::fprintf(stderr, "nano-simavr: cannot open a pseudo-terminal: %s\n", std::strerror(errno));
    return 1;
  }
  const std::string dir = pty_link.substr(0, pty_link.rfind('/'));
  if (pty_link.find('/') != std::string::npos && !dir.empty()) {
    for (size_t p = 1; p <= dir.size(); p++) {  // mkdir -p
      if (p == dir.size() || dir[p] == '/') mkdir(dir.substr(0, p).c_str(), 0755);
    }
  }
  unlink(pty_link.c_str());
  if (symlink(slave.c_str(), pty_link.c_str()) != 0) {
    std::fprintf(stderr, "nano-simavr: --pty '%s': cannot create the symlink: %s\n",
                 pty_link.c_str(), std::strerror(errno));
    return 1;
  }
  signal(SIGINT, on_signal);
  signal(SIGTERM, on_signal);
  signal(SIGPIPE, SIG_IGN);

  int rc = 0;
  try {
    sil::Board board(elf, imu);
    std::vector<uint8_t> out;
    board.set_uart_sink([&](uint8_t b, uint64_t) { out.push_back(b); });
    if (encoder_hz > 0) board.encoder_rate(encoder_hz, +1);
    std::printf("nano-simavr: %s on %s, linked at %s\n", elf.c_str(), slave.c_str(),
                pty_link.c_str());
    std::fflush(stdout);
    if (!bootloader.empty()) {
      // Held in reset until the uploader opens the port: a real Nano resets on the DTR pulse
      // of the open, before the uploader's first byte. A pty has no DTR; the uploader's
      // tcsetattr() (baud rate, raw mode) on the slave is the sign, or else its first byte.
      std::printf("nano-simavr: bootloader %s, waiting for the uploader\n", bootloader.c_str());
      std::fflush(stdout);
      termios idle{}, now{};
      tcgetattr(slave_fd, &idle);
      pollfd pfd{master, POLLIN, 0};
      while (!g_stop && poll(&pfd, 1, 10) == 0) {
        tcgetattr(slave_fd, &now);
        if (cfgetospeed(&now) != cfgetospeed(&idle) || now.c_lflag != idle.c_lflag) break;
      }
      board.boot_from(bootloader);
    }
    const uint64_t wall0 = mono_us();
    const uint64_t slice_us = 250;
    uint64_t dropped = 0;
    while (!g_stop) {
      uint8_t in[512];
      ssize_t n;
      while ((n = read(master, in, sizeof in)) > 0) board.send(in, static_cast<size_t>(n));
      if (!board.run_us(slice_us)) {
        std::fprintf(stderr, "nano-simavr: the simulated CPU stopped (crashed)\n");
        rc = 1;
        break;
      }
      size_t off = 0;
      while (off < out.size()) {
        ssize_t w = write(master, out.data() + off, out.size() - off);
        if (w <= 0) {
          dropped += out.size() - off;  // nobody reading and the pty buffer is full
          break;
        }
        off += static_cast<size_t>(w);
      }
      out.clear();
      board.clear_frames();
      const uint64_t sim_us = board.now_us();
      if (log != nullptr) {
        const uint64_t mono = mono_us();
        for (const auto &c : board.take_pwm_changes()) {
          std::fprintf(log, "%llu %llu %u %u %u %u\n",
                       static_cast<unsigned long long>(c.cycle / sil::kCyclesPerUs),
                       static_cast<unsigned long long>(mono), c.servo_ticks / 2u, c.motor_duty,
                       c.motor_reverse, c.motor_brake);
        }
        std::fflush(log);
      } else {
        board.take_pwm_changes();
      }
      if (duration_s > 0 && sim_us >= static_cast<uint64_t>(duration_s * 1e6)) break;
      if (speed > 0) {
        const uint64_t due = wall0 + static_cast<uint64_t>(static_cast<double>(sim_us) / speed);
        const uint64_t now = mono_us();
        if (due > now) usleep(static_cast<useconds_t>(due - now));
      }
    }
    if (dropped > 0)
      std::fprintf(stderr, "nano-simavr: %llu bytes dropped (no reader)\n",
                   static_cast<unsigned long long>(dropped));
  } catch (const std::exception &e) {
    std::fprintf(stderr, "nano-simavr: %s\n", e.what());
    rc = 1;
  }
  unlink(pty_link.c_str());
  if (log != nullptr) std::fclose(log);
  close(slave_fd);
  close(master);
  return rc;
}
