// nano-sil-bench: the firmware benchmark figures, all on the real ELF in simavr and in
// simulated time (so they do not depend on the machine's load). Progress on stderr, the last
// line of stdout is one JSON object. Used by tools/bench firmware.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "sil_board.h"

namespace {

using sil::Board;
using sil::make_command;
constexpr uint64_t kMs = 1000;

void stream(Board &b, uint16_t &seq, uint64_t duration_us, int16_t thr, int16_t steer,
            bool engaged) {
  for (uint64_t t = 0; t < duration_us; t += 10 * kMs) {
    b.send_command(make_command(seq++, thr, steer, engaged));
    b.run_us(10 * kMs);
  }
}

void arm(Board &b, uint16_t &seq) {
  b.run_us(20 * kMs);
  stream(b, seq, 30 * kMs, 0, 0, false);
  stream(b, seq, 30 * kMs, 0, 0, true);
}

template <typename T>
T median(std::vector<T> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? T{} : v[v.size() / 2];
}

// Frame's last byte on the wire -> OCR0A (motor duty) register changed, throttle 0 -> 1.0.
std::vector<double> measure_cmd_to_pwm(const std::string &elf, int samples) {
  Board b(elf);
  b.imu().set_sample({0, 0, 8192}, {0, 0, 0}, {100, 0, 0});
  uint16_t seq = 1;
  arm(b, seq);
  std::vector<double> out;
  for (int i = 0; i < samples; i++) {
    stream(b, seq, 300 * kMs, 0, 0, true);  // back to standstill (slew down takes 250 ms)
    b.run_us(static_cast<uint64_t>((i * 7919) % 9000));  // vary the phase against the loop
    b.take_pwm_changes();
    b.send_command(make_command(seq++, 1000, 0, true));
    b.run_until([&] { return b.tx_idle() && b.motor_duty() > 0; }, 20 * kMs);
    const uint64_t t0 = b.last_tx_byte_cycle();
    for (const auto &c : b.pwm_changes()) {
      if (c.cycle >= t0 && c.motor_duty > 0) {
        out.push_back(static_cast<double>(c.cycle - t0) / sil::kCyclesPerUs);
        break;
      }
    }
    stream(b, seq, 20 * kMs, 1000, 0, true);
  }
  return out;
}

// Last COMMAND's last byte -> motor duty 0 with the brake on (link lost while driving).
std::vector<double> measure_failsafe(const std::string &elf, int samples) {
  std::vector<double> out;
  for (int i = 0; i < samples; i++) {
    Board b(elf);
    uint16_t seq = 1;
    arm(b, seq);
    stream(b, seq, 300 * kMs, 600, 0, true);
    b.send_command(make_command(seq++, 600, 0, true));
    b.run_us(static_cast<uint64_t>(1000 + (i * 1777) % 8000));
    const uint64_t t0 = b.last_tx_byte_cycle();
    b.run_until([&] { return b.motor_duty() == 0 && b.motor_brake(); }, 500 * kMs);
    out.push_back(static_cast<double>(b.cycle() - t0) / sil::kCyclesPerUs / 1000.0);
  }
  return out;
}

struct LoadFigures {
  double telemetry_hz = 0, loop_hz = 0;
  uint32_t loop_cycles_p50 = 0, loop_cycles_p99 = 0;
  uint32_t loop_cycles_max = 0, isr_cycles_max = 0;
  uint32_t other_isr[4] = {0, 0, 0, 0};  // TIMER0_OVF, USART_RX, USART_UDRE, TWI
};

// Driving with everything on: IMU, encoders at edges_hz, commands at 100 Hz.
LoadFigures measure_load(const std::string &elf, double edges_hz, uint64_t duration_us) {
  Board b(elf);
  b.imu().set_sample({10, -20, 8192}, {5, -5, 3}, {120, 40, -300});
  uint16_t seq = 1;
  arm(b, seq);
  stream(b, seq, 300 * kMs, 500, 300, true);
  b.encoder_rate(edges_hz, +1);
  b.reset_cycle_stats();
  b.record_loop_cycles(true);
  const size_t states0 = b.count(PROTOCOL_ID_STATE);
  const uint64_t passes0 = b.loop_passes();
  const uint64_t t0 = b.now_us();
  for (uint64_t t = 0; t < duration_us; t += 10 * kMs) {
    const int16_t thr = static_cast<int16_t>(((t / (200 * kMs)) % 2) ? 800 : -400);
    b.send_command(make_command(seq++, thr, static_cast<int16_t>(thr / 2), true));
    b.run_us(10 * kMs);
  }
  LoadFigures f;
  const double secs = static_cast<double>(b.now_us() - t0) / 1e6;
  f.telemetry_hz = static_cast<double>(b.count(PROTOCOL_ID_STATE) - states0) / secs;
  f.loop_hz = static_cast<double>(b.loop_passes() - passes0) / secs;
  f.loop_cycles_max = b.loop_cycles_max();
  std::vector<uint32_t> passes = b.loop_cycles();
  std::sort(passes.begin(), passes.end());
  if (!passes.empty()) {
    f.loop_cycles_p50 = passes[passes.size() / 2];
    f.loop_cycles_p99 = passes[passes.size() * 99 / 100];
  }
  f.isr_cycles_max = b.enc_isr_cycles_max();
  const int vectors[4] = {16, 18, 19, 24};
  for (int i = 0; i < 4; i++) f.other_isr[i] = b.isr_cycles_max(vectors[i]);
  return f;
}

// True when edges at edges_hz on both wheels for 250 ms are all counted.
bool edges_all_counted(const std::string &elf, double edges_hz) {
  Board b(elf);
  b.imu().set_sample({0, 0, 8192}, {0, 0, 0}, {100, 0, 0});
  uint16_t seq = 1;
  arm(b, seq);
  b.encoder_rate(edges_hz, +1);
  stream(b, seq, 250 * kMs, 300, 0, true);
  b.encoder_rate(0);
  stream(b, seq, 30 * kMs, 300, 0, true);
  protocol_state_t s{};
  if (!b.last_state(&s)) return false;
  return s.enc_counts[0] == b.encoder_injected(0) && s.enc_counts[1] == b.encoder_injected(1);
}

}  // namespace

int main(int argc, char **argv) {
  if (argc != 2 || std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0) {
    std::fprintf(
        argc == 2 ? stdout : stderr,
        "usage: nano-sil-bench <firmware.elf>\n"
        "Measures the firmware in simavr (simulated time): cmd_to_pwm_us, failsafe_stop_ms,\n"
        "telemetry_hz, loop_cycles_max, encoder_isr_cycles_max, max_edge_rate_hz.\n"
        "Progress on stderr; the last stdout line is JSON.\n");
    return argc == 2 ? 0 : 2;
  }
  const std::string elf = argv[1];
  try {
    std::fprintf(stderr, "[bench] load: IMU + encoders 8000 edges/s + commands, 3 s simulated\n");
    const LoadFigures load = measure_load(elf, 8000, 3000 * kMs);
    std::fprintf(stderr,
                 "[bench]   telemetry %.1f Hz, loop %.0f passes/s, loop pass median %u / p99 %u / "
                 "max %u cycles (max %.0f us), encoder ISR max %u cycles\n",
                 load.telemetry_hz, load.loop_hz, load.loop_cycles_p50, load.loop_cycles_p99,
                 load.loop_cycles_max, load.loop_cycles_max / 16.0, load.isr_cycles_max);

    std::fprintf(stderr, "[bench] cmd_to_pwm: 31 samples\n");
    const auto c2p = measure_cmd_to_pwm(elf, 31);
    if (c2p.empty()) throw std::runtime_error("cmd_to_pwm: the motor never moved");
    std::fprintf(stderr, "[bench]   median %.0f us, min %.0f, max %.0f (n=%zu)\n", median(c2p),
                 *std::min_element(c2p.begin(), c2p.end()),
                 *std::max_element(c2p.begin(), c2p.end()), c2p.size());

    std::fprintf(stderr, "[bench] failsafe: 7 link losses\n");
    const auto fs = measure_failsafe(elf, 7);
    std::fprintf(stderr, "[bench]   median %.1f ms, max %.1f ms\n", median(fs),
                 *std::max_element(fs.begin(), fs.end()));

    std::fprintf(stderr, "[bench] encoder edge rate sweep (both wheels in step, 250 ms each)\n");
    double best = 0;
    uint32_t isr_max = load.isr_cycles_max;
    for (double hz = 10000; hz <= 400000; hz += 5000) {
      const bool ok = edges_all_counted(elf, hz);
      std::fprintf(stderr, "[bench]   %6.0f edges/s per wheel: %s\n", hz,
                   ok ? "all counted" : "LOST");
      if (!ok) break;
      best = hz;
    }
    // the ISR worst case under the load of the highest clean rate
    const LoadFigures fast = measure_load(elf, best > 0 ? best : 10000, 300 * kMs);
    isr_max = std::max(isr_max, fast.isr_cycles_max);
    const uint32_t loop_max = std::max(load.loop_cycles_max, fast.loop_cycles_max);
    std::fprintf(stderr, "[bench]   at %.0f edges/s: loop max %u cycles, ISR max %u cycles\n", best,
                 fast.loop_cycles_max, fast.isr_cycles_max);
    std::fprintf(
        stderr,
        "[bench]   other ISRs max [cycles]: TIMER0_OVF %u, USART_RX %u, USART_UDRE %u, TWI %u\n",
        fast.other_isr[0], fast.other_isr[1], fast.other_isr[2], fast.other_isr[3]);

    std::printf(
        "{\"encoder_isr_cycles_max\": %u, \"loop_cycles_max\": %u, \"cmd_to_pwm_us\": %.0f, "
        "\"failsafe_stop_ms\": %.1f, \"telemetry_hz\": %.1f, \"max_edge_rate_hz\": %.0f}\n",
        isr_max, loop_max, median(c2p), median(fs), load.telemetry_hz, best);
  } catch (const std::exception &e) {
    std::fprintf(stderr, "nano-sil-bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
