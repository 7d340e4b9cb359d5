#include "sil_board.h"

#include <cctype>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

extern "C" {
#include <simavr/avr_adc.h>
#include <simavr/avr_extint.h>
#include <simavr/avr_ioport.h>
#include <simavr/avr_uart.h>
#include <simavr/sim_avr.h>
#include <simavr/sim_elf.h>
#include <simavr/sim_io.h>
#include "nano_core_hal.h"
}

namespace sil {

namespace {
// ATmega328P data-space addresses of the registers the harness reads.
constexpr uint16_t kTccr0a = 0x44, kOcr0a = 0x47, kOcr1aL = 0x88, kOcr1aH = 0x89;
constexpr uint16_t kPortb = 0x25, kPortc = 0x28, kPortd = 0x2B;
constexpr uint8_t kCom0a1 = 0x80;
constexpr uint16_t kUcsr0a = 0xC0, kUbrr0l = 0xC4, kUbrr0h = 0xC5;
constexpr uint8_t kU2x0 = 0x02;
// 26 vectors of 2 words: the table ends at byte 0x68.
constexpr uint32_t kVectorTableBytes = 26 * 4;
// Quadrature phases (A, B) in forward order; A changes on 0->1 and 2->3.
constexpr uint8_t kPhaseA[4] = {0, 1, 1, 0};
constexpr uint8_t kPhaseB[4] = {0, 0, 1, 1};

void quiet_uart(avr_t *avr) {
  uint32_t flags = 0;
  avr_ioctl(avr, AVR_IOCTL_UART_GET_FLAGS('0'), &flags);
  flags &= ~static_cast<uint32_t>(AVR_UART_FLAG_STDIO);
  avr_ioctl(avr, AVR_IOCTL_UART_SET_FLAGS('0'), &flags);
}

// simavr's messages: errors to stderr, chatter ("Loaded 16746 .text ...") dropped so that the
// programs' stdout stays theirs.
void quiet_logger(avr_t *, const int level, const char *format, va_list ap) {
  if (level <= LOG_ERROR) std::vfprintf(stderr, format, ap);
}

void on_frame(const protocol_frame_t *f, void *ctx) {
  auto *b = static_cast<std::pair<Board *, std::vector<Frame> *> *>(ctx);
  b->second->push_back(Frame{b->first->cycle(), *f});
}
}  // namespace

Board::Board(const std::string &elf_path, bool imu_present) {
  avr_global_logger_set(quiet_logger);
  elf_firmware_t fw{};
  if (elf_read_firmware(elf_path.c_str(), &fw) != 0) {
    throw std::runtime_error("cannot load firmware ELF '" + elf_path + "'");
  }
  avr_ = avr_make_mcu_by_name("atmega328p");
  if (avr_ == nullptr) throw std::runtime_error("simavr has no atmega328p core");
  avr_init(avr_);
  avr_->log = LOG_NONE;
  fw.frequency = kCpuHz;
  avr_->frequency = kCpuHz;
  avr_->vcc = avr_->avcc = avr_->aref = 5000;  // [mV]
  avr_load_firmware(avr_, &fw);
  // simavr's default sleep callback usleep()s the host for the cycles a sleeping AVR skips;
  // the harness paces simulated time itself (nano-simavr --speed), so a sleep costs nothing.
  avr_->sleep = [](avr_t *, avr_cycle_count_t) {};
  avr_->log = LOG_NONE;
  for (uint32_t i = 0; i < fw.symbolcount; i++) {
    symbols_.emplace_back(fw.symbol[i]->symbol, fw.symbol[i]->addr);
    free(fw.symbol[i]);
  }
  free(fw.symbol);
  free(fw.flash);  // copied into the core by avr_load_firmware
  free(fw.eeprom);
  loop_addr_ = symbol("hal_avr_loop_once");
  quiet_uart(avr_);
  uart_in_ = avr_io_getirq(avr_, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_INPUT);
  avr_irq_register_notify(avr_io_getirq(avr_, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUTPUT),
                          &Board::uart_out_hook, this);
  // simavr 1.6 starts a per-cycle poll of INT0/INT1 when their pin goes low in level mode (the
  // reset default) and keeps it while the pin stays low, even after the firmware selects "any
  // change" (EICRA): 4x the host CPU per simulated second. The firmware uses no level mode.
  for (uint8_t i = 0; i < 2; i++) avr_extint_set_strict_lvl_trig(avr_, i, 0);
  for (int s = 0; s < 2; s++) {
    drive_pin(2 + s, 0);
    drive_pin(4 + s, 0);
  }
  imu_ = std::make_unique<Mpu9250>(avr_, imu_present);
  set_adc7_mv(2850);  // ~12.1 V pack through the 10k:3.3k divider
  protocol_parser_init(&parser_);
}

// Intel HEX data records into flash (types 00 data, 01 end, 02/04 extended addresses; 03/05
// start addresses are ignored: the AVR starts at its reset vector). Returns the lowest address
// written. simavr's own reader refuses the type-03 record of Debian's Optiboot image.
static uint32_t load_ihex(const std::string &path, uint8_t *flash, uint32_t flash_bytes) {
  FILE *f = std::fopen(path.c_str(), "r");
  if (f == nullptr) throw std::runtime_error("cannot read bootloader HEX '" + path + "'");
  char line[600];
  uint32_t base = 0, lowest = flash_bytes, line_no = 0;
  bool end = false;
  auto bad = [&](const char *why) {
    std::fclose(f);
    throw std::runtime_error("bootloader HEX '" + path + "' line " + std::to_string(line_no) +
                             ": " + why);
  };
  while (!end && std::fgets(line, sizeof line, f) != nullptr) {
    line_no++;
    if (line[0] != ':') continue;
    uint8_t rec[300];
    size_t n = 0;
    for (const char *c = line + 1;
         std::isxdigit(static_cast<unsigned char>(c[0])) &&
         std::isxdigit(static_cast<unsigned char>(c[1])) && n < sizeof rec;
         c += 2) {
      rec[n++] = static_cast<uint8_t>(std::strtoul(std::string(c, 2).c_str(), nullptr, 16));
    }
    if (n < 5 || n != static_cast<size_t>(rec[0]) + 5) bad("malformed record");
    uint8_t sum = 0;
    for (size_t k = 0; k < n; k++) sum = static_cast<uint8_t>(sum + rec[k]);
    if (sum != 0) bad("checksum");
    const uint32_t addr = static_cast<uint32_t>(rec[1] << 8 | rec[2]);
    switch (rec[3]) {
      case 0x00:
        if (base + addr + rec[0] > flash_bytes) bad("data beyond the flash");
        std::memcpy(flash + base + addr, rec + 4, rec[0]);
        if (base + addr < lowest) lowest = base + addr;
        break;
      case 0x01: end = true; break;
      case 0x02: base = static_cast<uint32_t>(rec[4] << 8 | rec[5]) << 4; break;
      case 0x04: base = static_cast<uint32_t>(rec[4] << 8 | rec[5]) << 16; break;
      default: break;  // 03, 05: start addresses
    }
  }
  std::fclose(f);
  if (lowest == flash_bytes) throw std::runtime_error("bootloader HEX '" + path + "' has no data");
  return lowest;
}

void Board::boot_from(const std::string &hex_path) {
  const uint32_t flash_bytes = avr_->flashend + 1;
  std::memset(avr_->flash, 0xFF, flash_bytes);
  const uint32_t start = load_ihex(hex_path, avr_->flash, flash_bytes);
  if (start < flash_bytes / 2) {
    throw std::runtime_error("'" + hex_path + "' is not a bootloader: it starts at " +
                             std::to_string(start) + ", below the boot section");
  }
  avr_->codeend = avr_->flashend;
  avr_->reset_pc = start;  // BOOTRST programmed: reset jumps into the bootloader
  avr_reset(avr_);
  quiet_uart(avr_);
  constexpr uint16_t kMcusr = 0x54;
  constexpr uint8_t kExtrf = 0x02;
  avr_->data[kMcusr] = kExtrf;  // reset pin pulled by DTR: the bootloader stays
  next_tx_cycle_ = cycle() + 1000 * kCyclesPerUs;
  wake_at(next_tx_cycle_, &tx_queue_);
}

Board::~Board() {
  if (avr_ != nullptr) {
    avr_terminate(avr_);
    free(avr_);  // avr_make_mcu_by_name() malloc()s the core
  }
}

uint64_t Board::cycle() const {
  return avr_->cycle;
}

uint32_t Board::symbol(const std::string &name) const {
  for (const auto &s : symbols_) {
    if (s.first == name) return s.second >= 0x800000 ? s.second - 0x800000 : s.second;
  }
  return 0;
}

void Board::write_ram(uint32_t addr, uint8_t v) {
  avr_->data[addr] = v;
}

void Board::set_adc7_mv(uint32_t mv) {
  avr_raise_irq(avr_io_getirq(avr_, AVR_IOCTL_ADC_GETIRQ, ADC_IRQ_ADC7), mv);
}

void Board::uart_out_hook(avr_irq_t *, uint32_t value, void *param) {
  static_cast<Board *>(param)->on_uart_byte(static_cast<uint8_t>(value));
}

void Board::on_uart_byte(uint8_t b) {
  uart_bytes_out_++;
  if (uart_sink_) uart_sink_(b, cycle());
  std::pair<Board *, std::vector<Frame> *> ctx{this, &frames_};
  protocol_parser_feed(&parser_, &b, 1, on_frame, &ctx);
}

void Board::send(const uint8_t *data, size_t n) {
  tx_queue_.insert(tx_queue_.end(), data, data + n);
  wake_at(next_tx_cycle_, &tx_queue_);
}

void Board::send_frame(uint8_t id, const uint8_t *payload, uint8_t len) {
  static uint8_t seq = 0;
  uint8_t buf[PROTOCOL_MAX_FRAME];
  size_t n = protocol_frame_encode(id, seq++, payload, len, buf, sizeof buf);
  if (n == 0) throw std::runtime_error("send_frame: payload too long");
  send(buf, n);
}

void Board::send_command(const protocol_command_t &c) {
  uint8_t p[PROTOCOL_LEN_COMMAND];
  protocol_command_pack(&c, p);
  send_frame(PROTOCOL_ID_COMMAND, p, PROTOCOL_LEN_COMMAND);
}

std::vector<protocol_state_t> Board::states() const {
  std::vector<protocol_state_t> out;
  for (const auto &fr : frames_) {
    protocol_state_t s;
    if (fr.f.id == PROTOCOL_ID_STATE && protocol_state_unpack(fr.f.payload, fr.f.len, &s) == 0) {
      out.push_back(s);
    }
  }
  return out;
}

bool Board::last_state(protocol_state_t *out) const {
  for (auto it = frames_.rbegin(); it != frames_.rend(); ++it) {
    if (it->f.id == PROTOCOL_ID_STATE)
      return protocol_state_unpack(it->f.payload, it->f.len, out) == 0;
  }
  return false;
}

size_t Board::count(uint8_t id) const {
  size_t n = 0;
  for (const auto &fr : frames_) n += fr.f.id == id;
  return n;
}

void Board::drive_pin(int bit, uint8_t level) {
  // Declared as the pin's external level too: simavr re-asserts an input's internal pull-up on
  // every PORTD write unless an external level is set, which would fake encoder edges.
  const uint8_t m = static_cast<uint8_t>(1u << bit);
  ext_level_d_ = static_cast<uint8_t>(level ? (ext_level_d_ | m) : (ext_level_d_ & ~m));
  avr_ioport_external_t ext{};
  ext.name = 'D';
  ext.mask = 0x3C;  // D2..D5
  ext.value = ext_level_d_;
  avr_ioctl(avr_, AVR_IOCTL_IOPORT_SET_EXTERNAL('D'), &ext);
  avr_raise_irq(avr_io_getirq(avr_, AVR_IOCTL_IOPORT_GETIRQ('D'), bit), level);
}

void Board::encoder_edge(int side, int dir) {
  // advance the quadrature until channel A has changed once
  for (;;) {
    uint8_t p = enc_phase_[side];
    uint8_t next = static_cast<uint8_t>((p + (dir > 0 ? 1 : 3)) & 3);
    enc_phase_[side] = next;
    bool a_changed = kPhaseA[p] != kPhaseA[next];
    if (a_changed) {
      enc_injected_[side] += dir > 0 ? 1 : -1;
      drive_pin(2 + side, kPhaseA[next]);
      return;
    }
    drive_pin(4 + side, kPhaseB[next]);
  }
}

void Board::encoder_rate(double edges_per_s, int dir) {
  enc_rate_ = edges_per_s;
  enc_dir_ = dir;
  // two quadrature steps (one A, one B change) per count, evenly spaced
  enc_phase_cycles_ = edges_per_s > 0 ? kCpuHz / (2.0 * edges_per_s) : 0;
  enc_next_cycle_ = cycle();
}

uint16_t Board::servo_pulse_us() const {
  return static_cast<uint16_t>((avr_->data[kOcr1aL] | avr_->data[kOcr1aH] << 8) / 2);
}
uint8_t Board::motor_duty() const {
  return (avr_->data[kTccr0a] & kCom0a1) ? avr_->data[kOcr0a] : 0;
}
bool Board::motor_reverse() const {
  return avr_->data[kPortd] & 0x80;
}
bool Board::motor_brake() const {
  return avr_->data[kPortb] & 0x01;
}

uint8_t Board::lamp_pins() const {
  const uint8_t b = avr_->data[kPortb], c = avr_->data[kPortc];
  uint8_t l = 0;
  if (b & 0x04) l |= NANO_CORE_LAMP_HEAD_LOW;
  if (b & 0x08) l |= NANO_CORE_LAMP_HEAD_HIGH;
  if (b & 0x10) l |= NANO_CORE_LAMP_TAIL;
  if (b & 0x20) l |= NANO_CORE_LAMP_REVERSE;
  if (c & 0x01) l |= NANO_CORE_LAMP_IND_LEFT;
  if (c & 0x02) l |= NANO_CORE_LAMP_IND_RIGHT;
  return l;
}

void Board::reset_cycle_stats() {
  loop_max_ = 0;
  loop_last_cycle_ = 0;
  loop_cycles_.clear();
  for (auto &m : isr_max_) m = 0;
}

void Board::sample_pwm() {
  PwmChange now{cycle(), static_cast<uint16_t>(avr_->data[kOcr1aL] | avr_->data[kOcr1aH] << 8),
                motor_duty(), motor_reverse(), motor_brake()};
  if (pwm_changes_.empty()) {
    pwm_changes_.push_back(now);
    return;
  }
  const PwmChange &last = pwm_changes_.back();
  if (last.servo_ticks != now.servo_ticks || last.motor_duty != now.motor_duty ||
      last.motor_reverse != now.motor_reverse || last.motor_brake != now.motor_brake) {
    pwm_changes_.push_back(now);
  }
}

// A no-op cycle timer: while the firmware sleeps, simavr jumps straight to its next cycle
// timer; these stop it at the harness's own next event (a UART byte, an encoder edge, the end
// of run_us), which the harness polls by cycle. One timer per tag (re-registering replaces).
static avr_cycle_count_t wake_for_harness(avr_t *, avr_cycle_count_t, void *) {
  return 0;
}

void Board::wake_at(uint64_t at_cycle, void *tag) {
  const uint64_t c = cycle();
  if (at_cycle > c) avr_cycle_timer_register(avr_, at_cycle - c, wake_for_harness, tag);
}

// One 8N1 byte on the wire at the baud rate the AVR has set (UBRR0, U2X0) [cycles]: 320 at the
// firmware's 500000 baud, 2780 at a bootloader's 57600, which must not get bytes faster than
// its wire rate while it writes a flash page.
uint64_t Board::uart_byte_cycles() const {
  const uint32_t ubrr = avr_->data[kUbrr0l] | (avr_->data[kUbrr0h] & 0x0Fu) << 8;
  const uint32_t cycles_per_bit = ((avr_->data[kUcsr0a] & kU2x0) ? 8u : 16u) * (ubrr + 1u);
  return 10u * cycles_per_bit;
}

void Board::step_io() {
  const uint64_t c = cycle();
  if (!tx_queue_.empty() && c >= next_tx_cycle_) {
    avr_raise_irq(uart_in_, tx_queue_.front());
    tx_queue_.pop_front();
    const uint64_t byte_cycles = uart_byte_cycles();
    next_tx_cycle_ = c + byte_cycles;
    if (tx_queue_.empty())
      last_tx_cycle_ = c + byte_cycles;  // stop bit done
    else
      wake_at(next_tx_cycle_, &tx_queue_);
  }
  if (enc_rate_ > 0 && c >= enc_next_cycle_) {
    for (int s = 0; s < 2; s++) {
      uint8_t p = enc_phase_[s];
      uint8_t next = static_cast<uint8_t>((p + (enc_dir_ > 0 ? 1 : 3)) & 3);
      enc_phase_[s] = next;
      if (kPhaseA[p] != kPhaseA[next]) {
        enc_injected_[s] += enc_dir_ > 0 ? 1 : -1;
        drive_pin(2 + s, kPhaseA[next]);
      } else {
        drive_pin(4 + s, kPhaseB[next]);
      }
    }
    enc_next_cycle_ =
        static_cast<uint64_t>(static_cast<double>(enc_next_cycle_) + enc_phase_cycles_);
    wake_at(enc_next_cycle_, &enc_next_cycle_);
  }
}

bool Board::run_us(uint64_t us, const std::function<bool()> &pred) {
  const uint64_t end = cycle() + us * kCyclesPerUs;
  wake_at(end, &run_end_tag_);
  uint32_t n = 0;
  while (cycle() < end) {
    step_io();
    const uint32_t pc_before = avr_->pc;
    const bool was_sleeping = avr_->state == cpu_Sleeping;
    const uint64_t cycle_before = avr_->cycle;
    const int state = avr_run(avr_);
    if (was_sleeping) loop_sleep_cycles_ += avr_->cycle - cycle_before;
    if (state == cpu_Done || state == cpu_Crashed) return false;
    const uint32_t pc = avr_->pc;
    if (pc != pc_before) {
      if (pc == 0) {
        resets_++;
        quiet_uart(avr_);
        isr_active_ = -1;
        loop_last_cycle_ = 0;
        loop_sleep_cycles_ = 0;
      } else if (pc < kVectorTableBytes && (pc & 3u) == 0) {  // entered an interrupt vector
        isr_active_ = static_cast<int>(pc / 4);
        // the 4-cycle interrupt response (datasheet) counts as part of the ISR
        isr_start_ = avr_->cycle - 4;
      } else if (pc == loop_addr_) {
        if (loop_last_cycle_ != 0) {  // a pass's busy cycles: ISRs in, sleep out
          const uint64_t d = avr_->cycle - loop_last_cycle_ - loop_sleep_cycles_;
          if (d > loop_max_) loop_max_ = static_cast<uint32_t>(d);
          if (record_loop_) loop_cycles_.push_back(static_cast<uint32_t>(d));
        }
        loop_last_cycle_ = avr_->cycle;
        loop_sleep_cycles_ = 0;
        loop_passes_++;
      }
    }
    if (isr_active_ >= 0 && avr_->sreg[S_I]) {  // RETI re-enabled interrupts
      const uint64_t d = avr_->cycle - isr_start_;
      if (d > isr_max_[isr_active_]) isr_max_[isr_active_] = static_cast<uint32_t>(d);
      isr_active_ = -1;
    }
    sample_pwm();
    if (pred && (++n & 63u) == 0 && pred()) return true;
  }
  return true;
}

protocol_command_t make_command(uint16_t seq, int16_t throttle_milli, int16_t steering_milli,
                                bool engaged, uint8_t headlights, uint8_t indicators) {
  protocol_command_t c{};
  c.seq = seq;
  c.throttle_milli = throttle_milli;
  c.steering_milli = steering_milli;
  c.headlights = headlights;
  c.indicators = indicators;
  c.flags = engaged ? PROTOCOL_CMD_ENGAGED : 0;
  return c;
}

}  // namespace sil
