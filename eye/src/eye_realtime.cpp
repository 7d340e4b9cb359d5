#include "eye_realtime.hpp"

#include <sched.h>

#include <cerrno>
#include <cstring>

namespace eye {

std::string request_realtime(int priority) {
  if (priority <= 0) return "";
  sched_param p{};
  p.sched_priority = priority;
  // Not SCHED_RESET_ON_FORK: it would reset the threads started afterwards too.
  if (sched_setscheduler(0, SCHED_FIFO, &p) == 0) return "";
  return std::strerror(errno);
}

}  // namespace eye
