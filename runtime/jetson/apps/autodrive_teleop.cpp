// autodrive-teleop: drive a car from a terminal keyboard and/or a gamepad (Linux joystick
// API), publishing <VEH>_COMMAND at a steady rate. Dead-man: release stops the car.
#include <autodrive/instance.hpp>
#include <autodrive/command_auth.hpp>
#include <autodrive_channels.h>
#include <CLI/CLI.hpp>
#include <fcntl.h>
#include <lcm/lcm-cpp.hpp>
#include <linux/joystick.h>
#include <linux/kd.h>
#include <sys/ioctl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>

#include <autodrive/core/clock.hpp>
#include <autodrive/teleop/teleop_mapper.hpp>

namespace {
volatile std::sig_atomic_t g_stop = 0;
void on_signal(int) {
  g_stop = 1;
}

// The platform's keyboard autorepeat delay [ms] and where it came from: the Linux console's
// (KDGKBREP on the terminal), else X11's (`xset q`, when DISPLAY is set); 0 when unknown.
int platform_autorepeat_delay_ms(int tty_fd, std::string *from) {
  kbd_repeat rep{-1, -1};
  if (::ioctl(tty_fd, KDKBDREP, &rep) == 0 && rep.delay > 0) {
    *from = "the Linux console";
    return rep.delay;
  }
  if (std::getenv("DISPLAY") == nullptr) return 0;
  FILE *xset = ::popen("xset q 2>/dev/null", "r");
  if (xset == nullptr) return 0;
  char line[256];
  int delay_ms = 0;
  while (std::fgets(line, sizeof line, xset))
    if (const char *at = std::strstr(line, "auto repeat delay:"))
      delay_ms = std::atoi(at + std::strlen("auto repeat delay:"));
  ::pclose(xset);
  if (delay_ms > 0) *from = "X11 (xset q)";
  return delay_ms;
}

// Puts the terminal in raw mode for single key presses; restores it on destruction.
class RawTerminal {
 public:
  explicit RawTerminal(int fd) : fd_(fd) {
    if (!isatty(fd_) || tcgetattr(fd_, &saved_) != 0) return;
    termios raw = saved_;
    cfmakeraw(&raw);
    raw.c_oflag |= OPOST;  // keep \n -> \r\n for our status lines
    raw.c_cc[VMIN] = 0;
    raw.c_cc[VTIME] = 0;
    active_ = tcsetattr(fd_, TCSANOW, &raw) == 0;
  }
  ~RawTerminal() {
    if (active_) tcsetattr(fd_, TCSANOW, &saved_);
  }
  bool active() const { return active_; }

 private:
  int fd_;
  termios saved_{};
  bool active_ = false;
};
}  // namespace

int main(int argc, char **argv) {
  CLI::App app{
      "autodrive-teleop: keyboard / gamepad teleop for a Nigel car, publishes <VEH>_COMMAND.\n"
      "Keyboard (hold keys; release = stop): w/s forward/back, a/d steer, space stop, +/- drive\n"
      "level, h headlights, z/c/x left/right/hazard indicators, q quit.\n"
      "Gamepad: hold the dead-man button (LB) and use left stick Y (throttle), right stick X\n"
      "(steering); A headlights, X/B/Y left/right/hazard indicators."};
  std::string vehicle = AUTODRIVE_VEHICLE_DEFAULT, url = AUTODRIVE_LCM_URL_DEFAULT, js_path,
              key_file, source = "teleop";
  double rate_hz = 50.0;
  bool no_keyboard = false, keys_stdin = false;
  int repeat_delay_ms = 0, key_hold_ms = 0;
  autodrive::teleop::Params p;
  app.add_option("--vehicle", vehicle, "vehicle name, channel prefix")->capture_default_str();
  app.add_option("--lcm-url", url, "LCM URL")->capture_default_str();
  app.add_option("--joystick", js_path, "gamepad device, e.g. /dev/input/js0");
  app.add_option("--rate-hz", rate_hz, "command publish rate [Hz]")
      ->check(CLI::Range(1.0, 500.0))
      ->capture_default_str();
  app.add_option("--max-throttle", p.max_throttle, "throttle at full stick / top key level [0,1]")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  app.add_option("--deadman-button", p.deadman_button, "gamepad dead-man button number")
      ->capture_default_str();
  app.add_flag("--no-keyboard", no_keyboard, "do not read the terminal");
  // A program that has the keyboard (autodrive-sim's window) writes the key bytes a terminal
  // would send, held keys repeated; the signing and the lease stay here
  // (docs/reference/simulator.md).
  app.add_flag("--keys-stdin", keys_stdin,
               "read key bytes from standard input even when it is a pipe, not a terminal "
               "(autodrive-sim --view's manual mode writes them); its end quits");
  app.add_option("--key-hold-ms", key_hold_ms,
                 "a repeating key counts as released after this long without a repeat [ms] "
                 "(default 600)")
      ->check(CLI::Range(50, 5000));
  app.add_option("--key-repeat-delay-ms", repeat_delay_ms,
                 "the keyboard's autorepeat delay [ms]: a fresh key press counts as held this "
                 "long + 150 ms before its first repeat (default: read from the Linux console or "
                 "X11, else 660, X11's default)")
      ->check(CLI::Range(50, 5000));
  app.add_option("--key-file", key_file,
                 "the car's command key (default: $AUTODRIVE_KEY_DIR/<VEH>.key, else "
                 "~/.config/autodrive/keys/<VEH>.key; tools/keys creates it)");
  app.add_option("--source", source,
                 "source id the commands are signed with (a person's: "
                 "takes control from the autonomy)")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  std::optional<autodrive::auth::Signer> signer;
  try {
    signer.emplace(autodrive::auth::load_key(
                       key_file.empty() ? autodrive::auth::default_key_path(vehicle) : key_file),
                   vehicle, source, autodrive::auth::kAuthorityPerson);
  } catch (const std::exception &e) {
    std::fprintf(stderr, "autodrive-teleop: %s\n", e.what());
    return 2;
  }
  url = autodrive::instance_lcm_url(url);  // AUTODRIVE_INSTANCE
  lcm::LCM lcm(url);
  if (!lcm.good()) {
    std::fprintf(stderr, "autodrive-teleop: LCM URL '%s' unusable\n", url.c_str());
    return 1;
  }
  int js = -1;
  if (!js_path.empty()) {
    js = ::open(js_path.c_str(), O_RDONLY | O_NONBLOCK);
    if (js < 0) {
      std::fprintf(stderr, "autodrive-teleop: cannot open gamepad %s: %m\n", js_path.c_str());
      return 1;
    }
  }
  if (no_keyboard && js < 0) {
    std::fprintf(stderr, "autodrive-teleop: --no-keyboard needs --joystick\n");
    return 2;
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  if (keys_stdin && no_keyboard) {
    std::fprintf(stderr,
                 "autodrive-teleop: --keys-stdin and --no-keyboard contradict each other\n");
    return 2;
  }
  RawTerminal term(STDIN_FILENO);
  const bool read_keys = !no_keyboard && (term.active() || keys_stdin);
  if (!no_keyboard && !read_keys)
    std::fprintf(stderr, "autodrive-teleop: stdin is not a terminal; keyboard disabled\n");
  if (repeat_delay_ms == 0) {
    std::string from;
    repeat_delay_ms = platform_autorepeat_delay_ms(STDIN_FILENO, &from);
    if (repeat_delay_ms > 0)
      std::fprintf(stderr, "autodrive-teleop: key autorepeat delay %d ms (from %s)\n",
                   repeat_delay_ms, from.c_str());
    else
      repeat_delay_ms = 660;  // X11's default; --key-repeat-delay-ms to change
  }
  p.key_first_hold_us = (repeat_delay_ms * 1000LL) + autodrive::teleop::kKeyRepeatMarginUs;
  if (key_hold_ms > 0) p.key_hold_us = key_hold_ms * 1000LL;
  autodrive::teleop::Mapper mapper(p);
  const std::string channel = vehicle + AUTODRIVE_CH_COMMAND_SUFFIX;
  const int64_t period_us = static_cast<int64_t>(1e6 / rate_hz);
  int64_t next_us = autodrive::clock::monotonic_us();
  bool running = true;
  while (running && !g_stop) {
    pollfd fds[2];
    nfds_t n = 0;
    if (read_keys) fds[n++] = {STDIN_FILENO, POLLIN, 0};
    if (js >= 0) fds[n++] = {js, POLLIN, 0};
    const int64_t wait_us = std::max<int64_t>(0, next_us - autodrive::clock::monotonic_us());
    ::poll(fds, n, static_cast<int>(wait_us / 1000));
    for (nfds_t i = 0; i < n; ++i) {
      if (fds[i].fd == STDIN_FILENO && (fds[i].revents & (POLLIN | POLLHUP))) {
        char buf[32];
        const ssize_t k = ::read(STDIN_FILENO, buf, sizeof buf);
        if (k == 0 && keys_stdin) running = false;  // the writer closed the pipe: hand back
        for (ssize_t j = 0; j < k; ++j)
          running = mapper.key(buf[j], autodrive::clock::monotonic_us()) && running;
      } else if (fds[i].fd == js && fds[i].revents) {
        js_event e;
        ssize_t k;
        while ((k = ::read(js, &e, sizeof e)) == sizeof e) {
          const int type = e.type & ~JS_EVENT_INIT;
          if (type == JS_EVENT_AXIS) mapper.js_axis(e.number, e.value);
          if (type == JS_EVENT_BUTTON) mapper.js_button(e.number, e.value != 0);
        }
        // lost: a device read fails once unplugged (ENODEV); a FIFO standing in for one
        // (tests/sim/test_window_gamepad.py) reaches its end when its writer closes it
        if (k == 0 || (k < 0 && errno != EAGAIN)) {
          std::fprintf(stderr, "\rautodrive-teleop: gamepad %s lost; stopping the car\n",
                       js_path.c_str());
          // the window that started us (--keys-stdin) reads our stdout for this line
          if (keys_stdin) {
            std::printf("gamepad lost\n");
            std::fflush(stdout);
          }
          mapper.js_lost();
          ::close(js);
          js = -1;
        }
      }
    }
    const int64_t now = autodrive::clock::monotonic_us();
    if (now >= next_us) {
      autodrive::vehicle_command_t c = mapper.command(now);
      c.utime = autodrive::clock::wall_us();
      signer->sign(c);
      lcm.publish(channel, &c);
      next_us = std::max(next_us + period_us, now);
      if (term.active() && c.seq % 10 == 0) {
        std::printf("\r%s thr %+5.2f steer %+5.2f %s lights %d ind %d level %.2f   ",
                    channel.c_str(), c.throttle, c.steering, c.engaged ? "ENGAGED " : "released",
                    c.headlights, c.indicators, mapper.key_level());
        std::fflush(stdout);
      }
    }
  }
  // Leave the car stopped: one last disengaged command.
  autodrive::vehicle_command_t c = mapper.command(autodrive::clock::monotonic_us());
  c.utime = autodrive::clock::wall_us();
  c.engaged = false;
  c.throttle = 0.0f;
  signer->sign(c);
  lcm.publish(channel, &c);
  if (js >= 0) ::close(js);
  std::printf("\n");
  return 0;
}
