// The frames a protocol_parser_feed() call delivers, collected for the codec tests.
#pragma once

#include <vector>

#include "protocol.h"

struct CollectedFrames {
  std::vector<protocol_frame_t> frames;
};

// protocol_parser_feed's frame callback: ctx is a CollectedFrames.
inline void collect_frame(const protocol_frame_t *f, void *ctx) {
  static_cast<CollectedFrames *>(ctx)->frames.push_back(*f);
}
