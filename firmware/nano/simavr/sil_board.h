// Firmware-in-the-loop board: the real Nigel Nano ELF running in simavr (ATmega328P at 16 MHz)
// with the Nano's surroundings emulated at the pin/peripheral level: UART0 bytes paced at the
// wire rate (500000 baud), quadrature encoder edges on D2-D5, an MPU-9250 on TWI, and readers
// for the servo (OCR1A), motor (OCR0A, D7 DIR, D8 BRK) and lamp pins. It also counts cycles
// per ISR (INT0/INT1) and per main-loop pass (entries of the hal_avr_loop_once symbol).
#pragma once
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <vector>

extern "C" {
#include "nano_core_hal.h"
#include "protocol.h"
}
#include "sil_imu.h"

struct avr_t;
struct avr_irq_t;

namespace sil {

constexpr uint32_t kCpuHz = 16000000;
constexpr uint64_t kCyclesPerUs = kCpuHz / 1000000;

struct Frame {
  uint64_t cycle;  // when its last byte left the AVR
  protocol_frame_t f;
};

struct PwmChange {  // an actuator register changed
  uint64_t cycle;
  uint16_t servo_ticks;  // OCR1A [0.5 us ticks]
  uint8_t motor_duty;    // OCR0A if the pin is connected, else 0
  uint8_t motor_reverse, motor_brake;
};

class Board {
 public:
  // Loads elf; throws std::runtime_error naming the file on failure.
  explicit Board(const std::string &elf_path, bool imu_present = true);
  ~Board();
  Board(const Board &) = delete;
  Board &operator=(const Board &) = delete;

  // Runs for a simulated duration; stops early if pred() becomes true (checked per instruction
  // batch). Returns false if the CPU crashed or stopped.
  bool run_us(uint64_t us, const std::function<bool()> &pred = nullptr);
  bool run_until(const std::function<bool()> &pred, uint64_t timeout_us) {
    return run_us(timeout_us, pred) && pred();
  }
  uint64_t cycle() const;
  uint64_t now_us() const { return cycle() / kCyclesPerUs; }

  // The Nano as it leaves the bootloader's reset: the application flash erased (0xFF), the
  // bootloader of hex_path (Intel HEX, e.g. Debian's Optiboot) at its address, BOOTRST (reset
  // vector = the bootloader) and MCUSR = EXTRF, as after the DTR pulse of an upload. The host's
  // bytes reach the UART from 1 ms on (the bootloader has set it up by then). Throws
  // std::runtime_error naming the file if it cannot be read or is not a bootloader.
  void boot_from(const std::string &hex_path);

  // UART into the AVR: bytes go out on the wire one byte-time apart.
  void send(const uint8_t *data, size_t n);
  void send_frame(uint8_t id, const uint8_t *payload, uint8_t len);
  void send_command(const protocol_command_t &c);
  bool tx_idle() const { return tx_queue_.empty(); }
  uint64_t last_tx_byte_cycle() const { return last_tx_cycle_; }

  // Frames decoded from the AVR's UART output, oldest first.
  const std::vector<Frame> &frames() const { return frames_; }
  void clear_frames() { frames_.clear(); }
  // Also hands every byte the AVR sends to sink (cycle = when it left the UART).
  void set_uart_sink(std::function<void(uint8_t, uint64_t)> sink) { uart_sink_ = std::move(sink); }
  std::vector<protocol_state_t> states() const;
  bool last_state(protocol_state_t *out) const;
  size_t count(uint8_t id) const;
  const protocol_stats_t &rx_stats() const { return parser_.stats; }
  size_t uart_bytes_out() const { return uart_bytes_out_; }

  // Encoders: one edge on channel A of a side (0 left, 1 right), direction + forward.
  void encoder_edge(int side, int dir);
  // Schedules edges on both wheels at edges_per_s [edges/s] each until stopped (0).
  void encoder_rate(double edges_per_s, int dir = 1);
  // A-channel edges injected so far, signed by direction [counts] (what the firmware should count).
  int64_t encoder_injected(int side) const { return enc_injected_[side]; }

  // Actuators as the AVR drives them now.
  uint16_t servo_pulse_us() const;
  uint8_t motor_duty() const;
  bool motor_reverse() const;
  bool motor_brake() const;
  uint8_t lamp_pins() const;  // NANO_CORE_LAMP_* bits from the pin levels
  const std::vector<PwmChange> &pwm_changes() const { return pwm_changes_; }
  // Hands over (and forgets) the changes recorded so far, for long runs.
  std::vector<PwmChange> take_pwm_changes() {
    std::vector<PwmChange> out;
    out.swap(pwm_changes_);
    if (!out.empty()) pwm_changes_.push_back(out.back());  // the reference for the next change
    return out;
  }

  Mpu9250 &imu() { return *imu_; }
  // Battery: sets the ADC7 input [mV at the pin].
  void set_adc7_mv(uint32_t mv);

  // Symbols of the ELF; 0 if absent. Data symbols are returned as SRAM addresses.
  uint32_t symbol(const std::string &name) const;
  void write_ram(uint32_t addr, uint8_t v);

  // Cycle statistics.
  // Longest run of an ISR [cycles], by vector number (1 INT0, 2 INT1, 16 TIMER0_OVF,
  // 18 USART_RX, 19 USART_UDRE, 24 TWI), from the vector to the RETI.
  uint32_t isr_cycles_max(int vector) const { return isr_max_[vector]; }
  uint32_t enc_isr_cycles_max() const {
    return isr_max_[1] > isr_max_[2] ? isr_max_[1] : isr_max_[2];
  }
  uint32_t loop_cycles_max() const { return loop_max_; }
  uint64_t loop_passes() const { return loop_passes_; }
  // Records every pass's length [cycles] (off by default: it grows by ~2400 entries/s).
  void record_loop_cycles(bool on) { record_loop_ = on; }
  const std::vector<uint32_t> &loop_cycles() const { return loop_cycles_; }
  void reset_cycle_stats();
  uint32_t resets() const { return resets_; }  // times the CPU went through its reset vector

  avr_t *avr() const { return avr_; }

 private:
  void step_io();
  uint64_t uart_byte_cycles() const;
  void drive_pin(int bit, uint8_t level);  // PORTD input pin driven from outside
  void on_uart_byte(uint8_t b);
  void sample_pwm();
  static void uart_out_hook(avr_irq_t *irq, uint32_t value, void *param);

  avr_t *avr_ = nullptr;
  std::unique_ptr<Mpu9250> imu_;
  std::vector<std::pair<std::string, uint32_t>> symbols_;
  avr_irq_t *uart_in_ = nullptr;
  uint8_t ext_level_d_ = 0;  // levels driven onto PD2..PD5
  int64_t enc_injected_[2]{};
  std::function<void(uint8_t, uint64_t)> uart_sink_;
  uint8_t enc_phase_[2]{};
  std::deque<uint8_t> tx_queue_;
  uint64_t next_tx_cycle_ = 0, last_tx_cycle_ = 0;
  uint8_t run_end_tag_ = 0;
  uint64_t loop_sleep_cycles_ = 0;  // cycles asleep since the last loop pass began  // address
                                    // only: the cycle-timer tag of run_us's end
  void wake_at(uint64_t at_cycle, void *tag);
  protocol_parser_t parser_{};
  std::vector<Frame> frames_;
  size_t uart_bytes_out_ = 0;
  double enc_rate_ = 0;
  int enc_dir_ = 1;
  uint64_t enc_next_cycle_ = 0;
  double enc_phase_cycles_ = 0;
  std::vector<PwmChange> pwm_changes_;
  uint32_t loop_addr_ = 0;
  uint64_t loop_last_cycle_ = 0;
  uint32_t loop_max_ = 0;
  bool record_loop_ = false;
  std::vector<uint32_t> loop_cycles_;
  uint64_t loop_passes_ = 0;
  int isr_active_ = -1;  // vector number of the ISR being timed
  uint64_t isr_start_ = 0;
  uint32_t isr_max_[26]{};
  uint32_t resets_ = 0;
};

// Builds the payload of a COMMAND.
protocol_command_t make_command(uint16_t seq, int16_t throttle_milli, int16_t steering_milli,
                                bool engaged, uint8_t headlights = 0, uint8_t indicators = 0);

}  // namespace sil
