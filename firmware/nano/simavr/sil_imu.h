// Emulated MPU-9250 (0x68) and its AK8963 magnetometer (0x0C) on simavr's TWI bus: register
// files with auto-increment, big-endian accel/gyro, little-endian mag, WHO_AM_I = 0x71.
// When absent it acknowledges nothing, like an unplugged board.
#pragma once
#include <array>
#include <cstdint>

struct avr_t;
struct avr_irq_t;

namespace sil {

class Mpu9250 {
 public:
  // Connects to the TWI of avr; present = answers on the bus.
  Mpu9250(avr_t *avr, bool present);
  void set_present(bool present) { present_ = present; }
  // Still acknowledges its address but no longer the register bytes written to it, like a
  // device that locked up mid-transfer.
  void set_stuck(bool stuck) { stuck_ = stuck; }
  // Raw readings [LSB] in the MPU's axes; mag in the AK8963's own axes.
  void set_sample(const std::array<int16_t, 3> &accel, const std::array<int16_t, 3> &gyro,
                  const std::array<int16_t, 3> &mag);
  uint8_t mpu_reg(uint8_t r) const { return mpu_[r & 0x7F]; }
  uint8_t ak_reg(uint8_t r) const { return ak_[r & 0x1F]; }
  uint32_t reads() const { return reads_; }  // bytes read by the master

 private:
  static void on_twi(avr_irq_t *irq, uint32_t value, void *param);
  void handle(uint32_t value);
  uint8_t *regs_of(uint8_t addr7);

  avr_t *avr_;
  avr_irq_t *to_avr_ = nullptr;
  bool present_;
  bool stuck_ = false;
  std::array<uint8_t, 128> mpu_{};
  std::array<uint8_t, 32> ak_{};
  uint8_t selected_ = 0;      // 7-bit address being talked to, 0 = none
  bool reg_pending_ = false;  // next written byte is the register pointer
  uint8_t ptr_ = 0;
  uint32_t reads_ = 0;
};

}  // namespace sil
