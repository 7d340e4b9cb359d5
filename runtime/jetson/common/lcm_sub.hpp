// Subscribes a member function through LCM's subscribeFunction. LCM 1.3.1's own
// member-function subscribe() breaks under GCC's UBSan vptr check (the callback receives a
// wrong subscription pointer and crashes), so every subscription in the runtime goes
// through this thunk instead.
#pragma once

#include <lcm/lcm-cpp.hpp>

#include <string>

namespace lcmsub {

template <class Msg, class Obj, void (Obj::*Method)(const Msg *)>
void thunk(const lcm::ReceiveBuffer *, const std::string &, const Msg *m, Obj *obj) {
  (obj->*Method)(m);
}

// Usage: lcmsub::subscribe<msg_t, Impl, &Impl::on_msg>(lcm, "CHANNEL", this);
template <class Msg, class Obj, void (Obj::*Method)(const Msg *)>
lcm::Subscription *subscribe(lcm::LCM &lcm, const std::string &channel, Obj *obj) {
  return lcm.subscribeFunction(channel, &thunk<Msg, Obj, Method>, obj);
}

}  // namespace lcmsub
