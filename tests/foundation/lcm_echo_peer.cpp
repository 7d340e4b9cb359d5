// LCM interop peer: receives autodrive::vehicle_command_t on <in> and republishes it on <out>
// with seq + 1, using Debian's C++ LCM 1.3.1. The Python side (PyPI lcm) drives it.
#include <lcm/lcm-cpp.hpp>

#include <autodrive/vehicle_command_t.hpp>

#include <cstdio>
#include <cstdlib>
#include <string>

namespace {
struct Echo {
  lcm::LCM *lcm;
  std::string out;
  int remaining;
};

// subscribeFunction, not the member-function subscribe(): LCM 1.3.1's member-function path
// hands its callback a null subscription under UBSan (see
// lcm_types/include/autodrive_lcm/subscribe.hpp).
void on_command(const lcm::ReceiveBuffer *, const std::string &,
                const autodrive::vehicle_command_t *m, Echo *echo) {
  autodrive::vehicle_command_t r = *m;
  r.seq = m->seq + 1;
  echo->lcm->publish(echo->out, &r);
  --echo->remaining;
}
}  // namespace

int main(int argc, char **argv) {
  if (argc != 5) {
    std::fprintf(stderr,
                 "usage: %s <lcm-url> <in-channel> <out-channel> <count>\n"
                 "Echoes vehicle_command_t from <in> to <out> with seq+1, <count> times.\n",
                 argv[0]);
    return 2;
  }
  lcm::LCM lcm(argv[1]);
  if (!lcm.good()) {
    std::fprintf(stderr, "lcm_echo_peer: cannot open LCM url '%s'\n", argv[1]);
    return 1;
  }
  Echo echo{&lcm, argv[3], std::atoi(argv[4])};
  lcm.subscribeFunction(argv[2], &on_command, &echo);
  std::printf("ready\n");
  std::fflush(stdout);
  while (echo.remaining > 0) {
    if (lcm.handleTimeout(5000) <= 0) {  // 5 s with nothing: the peer is gone
      std::fprintf(stderr, "lcm_echo_peer: no message for 5 s\n");
      return 1;
    }
  }
  return 0;
}
