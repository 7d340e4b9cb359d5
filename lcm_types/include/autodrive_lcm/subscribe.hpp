// Subscribing a member function to an LCM channel, safely.
// LCM 1.3.1's own member-function subscribe() hands its callback a null subscription under
// UBSan, so every C++ subscriber goes through subscribeFunction and this thunk instead.
// Messages are decoded here, not by LCM: LCM prints one stderr line per message that does
// not decode (a flood of garbage is a flood of lines); here each is counted and logged at a
// limited rate per channel ("dropped 2,431 malformed messages on X in the last 10 s").
#pragma once

#include <autodrive/log_limiter.hpp>
#include <lcm/lcm-cpp.hpp>

#include <string>

namespace autodrive_lcm {

// The process's log of messages that do not decode, one budget per channel. Call flush()
// now and then (a receive loop's timeout) so the summary of a flood that stopped is written.
inline autodrive::LogLimiter &malformed_log() {
  static autodrive::LogLimiter log("malformed messages");
  return log;
}

// Decodes the buffer as Msg; false (counted and logged per channel) if it does not decode.
template <class Msg>
bool decode(const lcm::ReceiveBuffer *rb, const std::string &channel, Msg *m) {
  const int len = static_cast<int>(rb->data_size);
  if (m->decode(rb->data, 0, len) == len) return true;
  malformed_log().event(channel, fmt::format("{} bytes do not decode as {}: dropped", rb->data_size,
                                             Msg::getTypeName()));
  return false;
}

template <class Msg, class Obj,
          void (Obj::*Method)(const lcm::ReceiveBuffer *, const std::string &, const Msg *)>
void member_thunk(const lcm::ReceiveBuffer *rb, const std::string &ch, Obj *o) {
  // value-initialised: decode() writes every field, but GCC cannot see that once a handler is
  // inlined (-Wmaybe-uninitialized on <VEH>_STATE's steering_applied in autodrive-marl)
  Msg m{};
  if (decode(rb, ch, &m)) (o->*Method)(rb, ch, &m);
}

// Usage: autodrive_lcm::subscribe<msg_t, Obj, &Obj::on_msg>(lcm, "CHANNEL", &obj);
template <class Msg, class Obj,
          void (Obj::*Method)(const lcm::ReceiveBuffer *, const std::string &, const Msg *)>
lcm::Subscription *subscribe(lcm::LCM &lcm, const std::string &channel, Obj *obj) {
  return lcm.subscribeFunction(channel, &member_thunk<Msg, Obj, Method>, obj);
}

template <class Msg, class Obj, void (Obj::*Method)(const Msg *)>
void message_thunk(const lcm::ReceiveBuffer *rb, const std::string &ch, Obj *o) {
  Msg m;
  if (decode(rb, ch, &m)) (o->*Method)(&m);
}

// The same for a handler that needs only the message: void Obj::on_msg(const msg_t *).
template <class Msg, class Obj, void (Obj::*Method)(const Msg *)>
lcm::Subscription *subscribe(lcm::LCM &lcm, const std::string &channel, Obj *obj) {
  return lcm.subscribeFunction(channel, &message_thunk<Msg, Obj, Method>, obj);
}

}  // namespace autodrive_lcm
