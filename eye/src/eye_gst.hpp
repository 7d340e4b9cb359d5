// A GStreamer pipeline as a frame source, through its own appsink: each frame is stamped with
// its buffer's PTS mapped to the system clock (the pipeline clock's time of that PTS, plus the
// system clock minus the pipeline clock), not the time the Eye pulled it. Built only when
// Debian's gstreamer-app-1.0 / gstreamer-video-1.0 dev files are found
// (AUTODRIVE_EYE_GST_APPSINK); without them `gst:` falls back to OpenCV's capture.
#pragma once
#include <memory>
#include <string>

#include "eye_source.hpp"

namespace eye {

// spec: the whole "gst:<pipeline>" (for messages). The pipeline must end in an appsink; it may
// deliver GRAY8, I420, NV12 (grey = the Y plane, no conversion), BGR or BGRx. idle_timeout_s: a
// pipeline with no frame for this long ends the stream (0: wait for EOS). Throws eye::Error
// naming the source if the pipeline cannot be parsed, has no appsink or does not start.
std::unique_ptr<Source> gst_source_open(const std::string &spec, const std::string &pipeline,
                                        double idle_timeout_s);

}  // namespace eye
