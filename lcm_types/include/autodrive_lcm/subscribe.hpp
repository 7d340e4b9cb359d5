// Subscribing a member function to an LCM channel, safely.
// LCM 1.3.1's own member-function subscribe() hands its callback a null subscription under
// UBSan, so every C++ subscriber goes through subscribeFunction and this thunk instead.
#pragma once

#include <lcm/lcm-cpp.hpp>

#include <string>

namespace autodrive_lcm {

template <class Msg, class Obj,
          void (Obj::*Method)(const lcm::ReceiveBuffer *, const std::string &, const Msg *)>
void member_thunk(const lcm::ReceiveBuffer *rb, const std::string &ch, const Msg *m, Obj *o) {
  (o->*Method)(rb, ch, m);
}

// Usage: autodrive_lcm::subscribe<msg_t, Obj, &Obj::on_msg>(lcm, "CHANNEL", &obj);
template <class Msg, class Obj,
          void (Obj::*Method)(const lcm::ReceiveBuffer *, const std::string &, const Msg *)>
lcm::Subscription *subscribe(lcm::LCM &lcm, const std::string &channel, Obj *obj) {
  return lcm.subscribeFunction(channel, &member_thunk<Msg, Obj, Method>, obj);
}

template <class Msg, class Obj, void (Obj::*Method)(const Msg *)>
void message_thunk(const lcm::ReceiveBuffer *, const std::string &, const Msg *m, Obj *o) {
  (o->*Method)(m);
}

// The same for a handler that needs only the message: void Obj::on_msg(const msg_t *).
template <class Msg, class Obj, void (Obj::*Method)(const Msg *)>
lcm::Subscription *subscribe(lcm::LCM &lcm, const std::string &channel, Obj *obj) {
  return lcm.subscribeFunction(channel, &message_thunk<Msg, Obj, Method>, obj);
}

}  // namespace autodrive_lcm
