#include "sil_imu.h"

extern "C" {
#include <simavr/avr_twi.h>
#include <simavr/sim_avr.h>
#include <simavr/sim_io.h>
}

namespace sil {

namespace {
constexpr uint8_t kMpuAddr = 0x68;
constexpr uint8_t kAkAddr = 0x0C;
void put_be(uint8_t *p, int16_t v) {
  p[0] = static_cast<uint8_t>(static_cast<uint16_t>(v) >> 8);
  p[1] = static_cast<uint8_t>(v);
}
void put_le(uint8_t *p, int16_t v) {
  p[0] = static_cast<uint8_t>(v);
  p[1] = static_cast<uint8_t>(static_cast<uint16_t>(v) >> 8);
}
}  // namespace

Mpu9250::Mpu9250(avr_t *avr, bool present) : avr_(avr), present_(present) {
  mpu_[0x75] = 0x71;  // WHO_AM_I of the MPU-9250
  mpu_[0x6B] = 0x40;  // PWR_MGMT_1 after power-up: asleep
  ak_[0x00] = 0x48;   // AK8963 WIA
  avr_irq_t *from_avr = avr_io_getirq(avr_, AVR_IOCTL_TWI_GETIRQ(0), TWI_IRQ_OUTPUT);
  to_avr_ = avr_io_getirq(avr_, AVR_IOCTL_TWI_GETIRQ(0), TWI_IRQ_INPUT);
  avr_irq_register_notify(from_avr, &Mpu9250::on_twi, this);
}

void Mpu9250::set_sample(const std::array<int16_t, 3> &accel, const std::array<int16_t, 3> &gyro,
                         const std::array<int16_t, 3> &mag) {
  for (int i = 0; i < 3; i++) {
    put_be(&mpu_[0x3B + 2 * i], accel[i]);
    put_be(&mpu_[0x43 + 2 * i], gyro[i]);
    put_le(&ak_[0x03 + 2 * i], mag[i]);
  }
  ak_[0x02] = 0x01;  // ST1: data ready
}

uint8_t *Mpu9250::regs_of(uint8_t addr7) {
  if (addr7 == kMpuAddr) return mpu_.data();
  if (addr7 == kAkAddr) return ak_.data();
  return nullptr;
}

void Mpu9250::on_twi(avr_irq_t *, uint32_t value, void *param) {
  static_cast<Mpu9250 *>(param)->handle(value);
}

void Mpu9250::handle(uint32_t value) {
  avr_twi_msg_irq_t msg;
  msg.u.v = value;
  const uint8_t cond = msg.u.twi.msg;
  if (cond & TWI_COND_STOP) {
    selected_ = 0;
    return;
  }
  if (cond & TWI_COND_START) {  // address phase: addr holds SLA+R/W
    selected_ = 0;
    const uint8_t addr7 = static_cast<uint8_t>(msg.u.twi.addr >> 1);
    if (present_ && regs_of(addr7) != nullptr) {
      selected_ = addr7;
      reg_pending_ = (msg.u.twi.addr & 1) == 0;
      avr_raise_irq(to_avr_, avr_twi_irq_msg(TWI_COND_ACK, msg.u.twi.addr, 1));
    }
    return;
  }
  if (selected_ == 0) return;
  uint8_t *regs = regs_of(selected_);
  const uint8_t mask = selected_ == kMpuAddr ? 0x7F : 0x1F;
  if (cond & TWI_COND_WRITE) {
    if (stuck_) {
      avr_raise_irq(to_avr_, avr_twi_irq_msg(TWI_COND_ACK, selected_, 0));  // NACK
      return;
    }
    avr_raise_irq(to_avr_, avr_twi_irq_msg(TWI_COND_ACK, selected_, 1));
    if (reg_pending_) {
      ptr_ = msg.u.twi.data & mask;
      reg_pending_ = false;
    } else {
      if (!(selected_ == kMpuAddr && ptr_ == 0x75)) regs[ptr_] = msg.u.twi.data;  // RO id
      ptr_ = static_cast<uint8_t>((ptr_ + 1) & mask);
    }
    return;
  }
  if (cond & TWI_COND_READ) {
    const uint8_t v = regs[ptr_];
    ptr_ = static_cast<uint8_t>((ptr_ + 1) & mask);
    reads_++;
    avr_raise_irq(to_avr_, avr_twi_irq_msg(TWI_COND_READ, selected_, v));
  }
}

}  // namespace sil
