#pragma once
#include <string>

namespace eye {

// Runs the calling thread, and every thread it starts afterwards (they inherit it), at
// SCHED_FIFO priority `priority` (1..98): a frame's poses then wait for no ordinary process,
// where on a busy 2-core machine they were late by tens of ms in 1 % of frames. 0: leave the
// scheduling as it is. Returns "" when granted, else why not (no CAP_SYS_NICE, no rtprio limit).
std::string request_realtime(int priority);

}  // namespace eye
