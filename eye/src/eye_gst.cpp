#include "eye_gst.hpp"

#include <gst/app/gstappsink.h>
#include <gst/gst.h>
#include <gst/video/video.h>
#include <opencv2/imgproc.hpp>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <mutex>

#include "eye_error.hpp"

namespace eye {

namespace {

// What the Eye can turn into grey: the Y plane of YUV formats is the grey image as it is.
constexpr const char *kCaps = "video/x-raw, format=(string){ GRAY8, I420, NV12, BGR, BGRx }";

std::string take_error(GError *e) {
  std::string s = e && e->message ? e->message : "unknown error";
  if (e) g_error_free(e);
  return s;
}

class GstSource : public Source {
 public:
  GstSource(const std::string &spec, const std::string &pipeline, double idle_s)
      : spec_(spec), idle_s_(idle_s) {
    static std::once_flag once;
    std::call_once(once, [] { gst_init(nullptr, nullptr); });
    GError *err = nullptr;
    pipe_ = gst_parse_launch(pipeline.c_str(), &err);
    if (err) {
      const std::string why = take_error(err);
      if (pipe_) gst_object_unref(pipe_);
      pipe_ = nullptr;
      throw Error("source '" + spec_ + "': cannot parse the pipeline: " + why);
    }
    sink_ = find_appsink();
    if (!sink_) {
      gst_object_unref(pipe_);
      throw Error("source '" + spec_ + "': the pipeline has no appsink (end it with '! appsink')");
    }
    GstCaps *caps = gst_caps_from_string(kCaps);
    gst_app_sink_set_caps(GST_APP_SINK(sink_), caps);
    gst_caps_unref(caps);
    // A short queue and back-pressure: no frame is dropped here, a slow Eye slows the source.
    gst_app_sink_set_max_buffers(GST_APP_SINK(sink_), 2);
    gst_app_sink_set_drop(GST_APP_SINK(sink_), FALSE);
    if (gst_element_set_state(pipe_, GST_STATE_PLAYING) == GST_STATE_CHANGE_FAILURE ||
        gst_element_get_state(pipe_, nullptr, nullptr, 10 * GST_SECOND) ==
            GST_STATE_CHANGE_FAILURE) {
      const std::string why = bus_error();
      close();
      throw Error("source '" + spec_ + "': the pipeline does not start" +
                  (why.empty() ? std::string() : ": " + why));
    }
  }
  ~GstSource() override { close(); }

  bool next(Frame *f) override {
    const auto start = std::chrono::steady_clock::now();
    GstSample *sample = nullptr;
    while (!(sample = gst_app_sink_try_pull_sample(GST_APP_SINK(sink_), 100 * GST_MSECOND))) {
      const std::string why = bus_error();
      if (!why.empty()) throw Error("source '" + spec_ + "': " + why);
      if (gst_app_sink_is_eos(GST_APP_SINK(sink_))) return false;
      const double waited =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (idle_s_ > 0 && waited > idle_s_) return false;
    }
    const int64_t grabbed_utime = now_utime();
    bool ok = to_gray(sample, &f->gray);
    f->utime = ok ? capture_utime(sample, grabbed_utime) : 0;
    gst_sample_unref(sample);
    if (!ok) throw Error("source '" + spec_ + "': a frame without video caps or data");
    f->wall_clock = true;
    f->label = spec_.substr(0, 4) + "#" + std::to_string(n_++);
    return true;
  }

 private:
  GstElement *find_appsink() {
    GstIterator *it = gst_bin_iterate_sinks(GST_BIN(pipe_));
    GValue v = G_VALUE_INIT;
    GstElement *found = nullptr;
    while (!found && gst_iterator_next(it, &v) == GST_ITERATOR_OK) {
      auto *e = GST_ELEMENT(g_value_get_object(&v));
      if (GST_IS_APP_SINK(e)) found = GST_ELEMENT(gst_object_ref(e));
      g_value_reset(&v);
    }
    g_value_unset(&v);
    gst_iterator_free(it);
    return found;
  }

  // The first error on the pipeline's bus ("" if none), with its element's name.
  std::string bus_error() {
    GstBus *bus = gst_element_get_bus(pipe_);
    GstMessage *m = gst_bus_pop_filtered(bus, GST_MESSAGE_ERROR);
    gst_object_unref(bus);
    if (!m) return "";
    GError *e = nullptr;
    gst_message_parse_error(m, &e, nullptr);
    const std::string who = GST_OBJECT_NAME(m->src) ? GST_OBJECT_NAME(m->src) : "?";
    gst_message_unref(m);
    return who + ": " + take_error(e);
  }

  // The buffer's PTS as a time on the system clock [us]. A PTS is in its segment's time; its
  // running time + the pipeline's base time is the pipeline clock's time of the PTS (for a live
  // camera: when the frame was taken). The pipeline clock (GStreamer's system clock, monotonic)
  // is mapped to the system clock by their offset (clock_offset).
  int64_t capture_utime(GstSample *s, int64_t grabbed_utime) {
    GstBuffer *b = gst_sample_get_buffer(s);
    const GstSegment *seg = gst_sample_get_segment(s);
    GstClock *clock = gst_element_get_clock(pipe_);
    const GstClockTime pts = GST_BUFFER_PTS(b);
    const GstClockTime running = GST_CLOCK_TIME_IS_VALID(pts) && seg
                                     ? gst_segment_to_running_time(seg, GST_FORMAT_TIME, pts)
                                     : GST_CLOCK_TIME_NONE;
    int64_t utime = grabbed_utime;
    if (clock && GST_CLOCK_TIME_IS_VALID(running)) {
      if (clock != offset_clock_) clock_offset(clock);
      const auto pts_clock = static_cast<int64_t>(gst_element_get_base_time(pipe_) + running);
      utime = pts_clock / 1000 + offset_us_;
    } else if (!warned_no_pts_) {
      warned_no_pts_ = true;
      std::fprintf(stderr,
                   "autodrive-eye: %s: buffers without a PTS (or no pipeline clock): frames are "
                   "stamped with the time they are pulled\n",
                   spec_.c_str());
    }
    if (clock) gst_object_unref(clock);
    return utime;
  }

  // System clock minus pipeline clock [us], read once per clock: the tightest of a few
  // (clock, system, clock) reads, so a preemption between two reads cannot shift every stamp.
  void clock_offset(GstClock *clock) {
    int64_t best_span = INT64_MAX;
    for (int k = 0; k < 5; ++k) {
      const auto c0 = static_cast<int64_t>(gst_clock_get_time(clock));
      const int64_t sys = now_utime();
      const auto c1 = static_cast<int64_t>(gst_clock_get_time(clock));
      if (c1 - c0 < best_span) {
        best_span = c1 - c0;
        offset_us_ = sys - (c0 + c1) / 2000;
      }
    }
    offset_clock_ = clock;  // compared only, never dereferenced: the pipeline keeps its clock
  }

  // Grey copy of the sample's frame (the buffer is unmapped after).
  static bool to_gray(GstSample *s, cv::Mat *gray) {
    GstVideoInfo info;
    GstCaps *caps = gst_sample_get_caps(s);
    GstBuffer *b = gst_sample_get_buffer(s);
    if (!caps || !b || !gst_video_info_from_caps(&info, caps)) return false;
    GstVideoFrame vf;
    if (!gst_video_frame_map(&vf, &info, b, GST_MAP_READ)) return false;
    const int w = GST_VIDEO_INFO_WIDTH(&info), h = GST_VIDEO_INFO_HEIGHT(&info);
    const auto stride = static_cast<size_t>(GST_VIDEO_FRAME_PLANE_STRIDE(&vf, 0));
    void *p0 = GST_VIDEO_FRAME_PLANE_DATA(&vf, 0);
    switch (GST_VIDEO_INFO_FORMAT(&info)) {
      case GST_VIDEO_FORMAT_GRAY8:
      case GST_VIDEO_FORMAT_I420:
      case GST_VIDEO_FORMAT_NV12: cv::Mat(h, w, CV_8UC1, p0, stride).copyTo(*gray); break;
      case GST_VIDEO_FORMAT_BGR:
        cv::cvtColor(cv::Mat(h, w, CV_8UC3, p0, stride), *gray, cv::COLOR_BGR2GRAY);
        break;
      case GST_VIDEO_FORMAT_BGRx:
        cv::cvtColor(cv::Mat(h, w, CV_8UC4, p0, stride), *gray, cv::COLOR_BGRA2GRAY);
        break;
      default: gst_video_frame_unmap(&vf); return false;
    }
    gst_video_frame_unmap(&vf);
    return true;
  }

  void close() {
    if (pipe_) {
      gst_element_set_state(pipe_, GST_STATE_NULL);
      gst_object_unref(pipe_);
      pipe_ = nullptr;
    }
    if (sink_) {
      gst_object_unref(sink_);
      sink_ = nullptr;
    }
  }

  std::string spec_;
  double idle_s_;
  GstElement *pipe_ = nullptr, *sink_ = nullptr;
  long n_ = 0;
  bool warned_no_pts_ = false;
  const GstClock *offset_clock_ = nullptr;  // the clock offset_us_ was read for
  int64_t offset_us_ = 0;
};

}  // namespace

std::unique_ptr<Source> gst_source_open(const std::string &spec, const std::string &pipeline,
                                        double idle_timeout_s) {
  return std::make_unique<GstSource>(spec, pipeline, idle_timeout_s);
}

}  // namespace eye
