// The frames a proto_parser_feed() call delivers, collected for the codec tests.
#pragma once

#include <vector>

#include "proto.h"

struct CollectedFrames {
  std::vector<proto_frame_t> frames;
};

// proto_parser_feed's frame callback: ctx is a CollectedFrames.
inline void collect_frame(const proto_frame_t *f, void *ctx) {
  static_cast<CollectedFrames *>(ctx)->frames.push_back(*f);
}
