#include "sketchnav/drivers/aravis_camera.h"

#include <arpa/inet.h>
#include <arv.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <opencv2/imgproc.hpp>

#include <atomic>
#include <cmath>
#include <condition_variable>
#include <mutex>
#include <sstream>
#include <thread>

#include "sketchnav/core/config.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/log.h"

namespace sketchnav::drivers {

void AravisParams::validate() const {
  require(width >= 0, "camera.aravis.width", "must be >= 0 (0 keeps the camera's)");
  require(height >= 0, "camera.aravis.height", "must be >= 0 (0 keeps the camera's)");
  require(fps >= 0 && fps <= 1000, "camera.aravis.fps", "must be in [0, 1000] Hz");
  require(exposure_us >= 0, "camera.aravis.exposure_us", "must be >= 0");
  require(buffers >= 2 && buffers <= 256, "camera.aravis.buffers", "must be in [2, 256]");
  require(packet_size == 0 || (packet_size >= 576 && packet_size <= 65000),
          "camera.aravis.packet_size", "must be 0 or in [576, 65000] bytes");
  require(hfov_deg > 1 && hfov_deg < 179, "camera.aravis.hfov_deg", "must be in (1, 179) deg");
  require(lost_timeout_s > 0, "camera.aravis.lost_timeout_s", "must be positive");
  require(reconnect_period_s > 0, "camera.aravis.reconnect_period_s", "must be positive");
}

void AravisParams::applyUri(const Uri& uri) {
  pixel_format = uri.param("pixel_format", pixel_format);
  width = uri.paramInt("width", width);
  height = uri.paramInt("height", height);
  fps = uri.paramDouble("fps", fps);
  exposure_us = uri.paramDouble("exposure_us", exposure_us);
  gain_db = uri.paramDouble("gain_db", gain_db);
  buffers = uri.paramInt("buffers", buffers);
  packet_size = uri.paramInt("packet_size", packet_size);
  resend = uri.paramInt("resend", resend ? 1 : 0) != 0;
  hfov_deg = uri.paramDouble("hfov_deg", hfov_deg);
  lost_timeout_s = uri.paramDouble("lost_timeout_s", lost_timeout_s);
  reconnect_period_s = uri.paramDouble("reconnect_period_s", reconnect_period_s);
}

namespace {

// 0.2 rather than std::to_string's 0.200000, for messages.
std::string shortNumber(double x) {
  std::ostringstream o;
  o << x;
  return o.str();
}

bool isIPv4(const std::string& s) {
  in_addr a{};
  return ::inet_pton(AF_INET, s.c_str(), &a) == 1;
}

// The local address the kernel would use to reach `device` (a connected UDP socket sends
// nothing): the interface Aravis must listen on, found without any discovery broadcast.
std::string localAddressFor(const std::string& device) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  if (fd < 0) return "0.0.0.0";
  sockaddr_in dst{};
  dst.sin_family = AF_INET;
  dst.sin_port = htons(3956);
  ::inet_pton(AF_INET, device.c_str(), &dst.sin_addr);
  std::string out = "0.0.0.0";
  if (::connect(fd, reinterpret_cast<sockaddr*>(&dst), sizeof dst) == 0) {
    sockaddr_in local{};
    socklen_t len = sizeof local;
    if (::getsockname(fd, reinterpret_cast<sockaddr*>(&local), &len) == 0) {
      char buf[INET_ADDRSTRLEN] = {0};
      ::inet_ntop(AF_INET, &local.sin_addr, buf, sizeof buf);
      out = buf;
    }
  }
  ::close(fd);
  return out;
}

std::string takeError(GError*& e) {
  std::string s = e ? e->message : "unknown error";
  if (e) g_clear_error(&e);
  return s;
}

struct Opened {
  ArvCamera* camera = nullptr;
  ArvStream* stream = nullptr;
  Intrinsics intrinsics;     // of the configured region
  std::string pixel_format;  // what the camera streams
};

void closeOpened(Opened& o) {
  if (o.camera) {
    GError* e = nullptr;
    arv_camera_stop_acquisition(o.camera, &e);
    g_clear_error(&e);
  }
  if (o.stream) g_object_unref(o.stream);
  if (o.camera) g_object_unref(o.camera);
  o = {};
}

}  // namespace

struct AravisCamera::Impl {
  std::string device;
  AravisParams params;
  std::shared_ptr<Clock> clock;
  std::string uri;

  std::mutex mutex;  // guards `cam`, stats, state below
  Opened cam;
  gulong lost_handler = 0;
  std::atomic<bool> control_lost{false};
  bool up = false;            // frames are flowing (as last reported to the callback)
  double last_frame_t = 0.0;  // [s] clock time of the last buffer (any status)
  std::uint64_t last_frame_id = 0;
  bool have_frame_id = false;
  std::uint64_t seq = 0, reconnects = 0, underruns_base = 0;
  double latency_sum_ms = 0.0;
  std::uint64_t latency_n = 0;
  DeviceStats stats;
  Intrinsics intrinsics;
  std::string pixel_format;
  std::function<void(bool)> callback;

  std::thread reconnector;
  std::atomic<bool> quitting{false};
  std::atomic<bool> reconnecting{false};
  Opened pending;  // a camera reopened by the reconnector, handed over in grab()

  static void onControlLost(ArvDevice*, gpointer self) {
    static_cast<Impl*>(self)->control_lost = true;
  }

  // Opens, configures and starts streaming; throws RuntimeError / InputError.
  Opened open() {
    GError* e = nullptr;
    ArvCamera* camera = nullptr;
    if (isIPv4(device)) {
      const std::string local = localAddressFor(device);
      GInetAddress* iaddr = g_inet_address_new_from_string(local.c_str());
      GInetAddress* daddr = g_inet_address_new_from_string(device.c_str());
      ArvDevice* dev = arv_gv_device_new(iaddr, daddr, &e);
      g_object_unref(iaddr);
      g_object_unref(daddr);
      if (!dev)
        throw RuntimeError("camera '" + uri + "': cannot open GigE Vision device " + device + ": " +
                           takeError(e));
      camera = arv_camera_new_with_device(dev, &e);
      g_object_unref(dev);  // the camera holds its own reference
    } else if (device.rfind("Fake_", 0) == 0) {
      ArvDevice* dev = arv_fake_device_new(device.substr(5).c_str(), &e);
      if (!dev) throw RuntimeError("camera '" + uri + "': " + takeError(e));
      camera = arv_camera_new_with_device(dev, &e);
      g_object_unref(dev);
    } else {
      camera = arv_camera_new(device.c_str(), &e);
    }
    if (!camera)
      throw RuntimeError("camera '" + uri + "': cannot open Aravis device '" + device +
                         "': " + takeError(e));
    Opened o;
    o.camera = camera;
    try {
      configure(o);
      o.stream = arv_camera_create_stream(camera, nullptr, nullptr, &e);
      if (!o.stream)
        throw RuntimeError("camera '" + uri + "': cannot create stream: " + takeError(e));
      if (ARV_IS_GV_STREAM(o.stream))
        g_object_set(
            o.stream, "packet-resend",
            params.resend ? ARV_GV_STREAM_PACKET_RESEND_ALWAYS : ARV_GV_STREAM_PACKET_RESEND_NEVER,
            nullptr);
      const guint payload = arv_camera_get_payload(camera, &e);
      if (e) throw RuntimeError("camera '" + uri + "': " + takeError(e));
      for (int i = 0; i < params.buffers; ++i)
        arv_stream_push_buffer(o.stream, arv_buffer_new_allocate(payload));
      arv_camera_set_acquisition_mode(camera, ARV_ACQUISITION_MODE_CONTINUOUS, &e);
      g_clear_error(&e);
      arv_camera_start_acquisition(camera, &e);
      if (e) throw RuntimeError("camera '" + uri + "': cannot start acquisition: " + takeError(e));
    } catch (...) {
      closeOpened(o);
      throw;
    }
    return o;
  }

  void check(GError*& e, const char* field) {
    if (e)
      throw InputError("camera '" + uri + "': camera refused camera.aravis." + field + ": " +
                       takeError(e));
  }

  // Applies the params; records the resulting size and format in `o`.
  void configure(Opened& o) {
    ArvCamera* c = o.camera;
    GError* e = nullptr;
    if (!params.pixel_format.empty()) {
      arv_camera_set_pixel_format_from_string(c, params.pixel_format.c_str(), &e);
      check(e, "pixel_format");
    }
    if (params.width > 0 || params.height > 0) {
      gint x, y, w, h;
      arv_camera_get_region(c, &x, &y, &w, &h, &e);
      check(e, "width");
      arv_camera_set_region(c, 0, 0, params.width > 0 ? params.width : w,
                            params.height > 0 ? params.height : h, &e);
      check(e, params.width > 0 ? "width" : "height");
    }
    if (params.fps > 0) {
      arv_camera_set_frame_rate(c, params.fps, &e);
      check(e, "fps");
    }
    if (params.exposure_us > 0) {
      arv_camera_set_exposure_time(c, params.exposure_us, &e);
      check(e, "exposure_us");
    }
    if (params.gain_db >= 0) {
      arv_camera_set_gain(c, params.gain_db, &e);
      check(e, "gain_db");
    }
    if (params.packet_size > 0 && arv_camera_is_gv_device(c)) {
      arv_camera_gv_set_packet_size(c, params.packet_size, &e);
      check(e, "packet_size");
    }
    gint x, y, w, h;
    arv_camera_get_region(c, &x, &y, &w, &h, &e);
    g_clear_error(&e);
    o.intrinsics = Intrinsics::fromFov(w, h, params.hfov_deg * M_PI / 180.0);
    const char* pf = arv_camera_get_pixel_format_as_string(c, &e);
    g_clear_error(&e);
    o.pixel_format = pf ? pf : "";
  }

  // Called with the mutex held: `o` becomes the streaming camera.
  void adopt(Opened o) {
    cam = o;
    intrinsics = o.intrinsics;
    pixel_format = o.pixel_format;
    control_lost = false;
    lost_handler = g_signal_connect(arv_camera_get_device(cam.camera), "control-lost",
                                    G_CALLBACK(&Impl::onControlLost), this);
    last_frame_t = clock->now();
    have_frame_id = false;
    underruns_base = 0;
  }

  void disconnectSignal() {
    if (cam.camera && lost_handler) {
      g_signal_handler_disconnect(arv_camera_get_device(cam.camera), lost_handler);
      lost_handler = 0;
    }
  }

  void setUp(bool now_up) {
    if (now_up == up) return;
    up = now_up;
    if (callback) callback(up);
  }

  // Called with the mutex held: the camera is gone; free it, tell the owner, start reopening.
  void lose(const std::string& why) {
    log::warn("aravis", "camera lost, reconnecting", {{"uri", uri}, {"why", why}});
    stats.last_error = "camera lost: " + why;
    disconnectSignal();
    Opened old = cam;
    cam = {};
    setUp(false);
    // Freeing a dead GigE device can block on GVCP retries: do it on the reconnector too.
    startReconnector(old);
  }

  void startReconnector(Opened old) {
    if (reconnecting.exchange(true)) {
      closeOpened(old);
      return;
    }
    if (reconnector.joinable()) reconnector.join();
    reconnector = std::thread([this, old]() mutable {
      closeOpened(old);
      SteadyClock wall;
      while (!quitting) {
        try {
          Opened o = open();
          std::lock_guard<std::mutex> lock(mutex);
          pending = o;
          break;
        } catch (const std::exception& ex) {
          log::debug("aravis", "reopen failed", {{"uri", uri}, {"why", ex.what()}});
        }
        const double until = wall.now() + params.reconnect_period_s;
        while (!quitting && wall.now() < until) wall.sleepUntil(wall.now() + 0.02);
      }
      reconnecting = false;
    });
  }

  // Converts one successful buffer to BGR; false (with a reason) when it cannot.
  bool convert(ArvBuffer* b, cv::Mat& out, std::string& why) {
    size_t size = 0;
    const void* data = arv_buffer_get_image_data(b, &size);
    const int w = arv_buffer_get_image_width(b), h = arv_buffer_get_image_height(b);
    const ArvPixelFormat pf = arv_buffer_get_image_pixel_format(b);
    if (!data || w <= 0 || h <= 0) return (why = "buffer without image data", false);
    const std::size_t bpp = ARV_PIXEL_FORMAT_BIT_PER_PIXEL(pf);
    if (size < static_cast<std::size_t>(w) * h * bpp / 8)
      return (why = "image data shorter than its size", false);
    void* p = const_cast<void*>(data);
    // OpenCV names a Bayer pattern by its second row, so sensor RGGB is COLOR_BayerBG2BGR.
    switch (pf) {
      case ARV_PIXEL_FORMAT_MONO_8:
        cv::cvtColor(cv::Mat(h, w, CV_8UC1, p), out, cv::COLOR_GRAY2BGR);
        break;
      case ARV_PIXEL_FORMAT_MONO_16: {
        cv::Mat m8;
        cv::Mat(h, w, CV_16UC1, p).convertTo(m8, CV_8U, 1.0 / 256.0);
        cv::cvtColor(m8, out, cv::COLOR_GRAY2BGR);
        break;
      }
      case ARV_PIXEL_FORMAT_BAYER_RG_8:
        cv::cvtColor(cv::Mat(h, w, CV_8UC1, p), out, cv::COLOR_BayerBG2BGR);
        break;
      case ARV_PIXEL_FORMAT_BAYER_BG_8:
        cv::cvtColor(cv::Mat(h, w, CV_8UC1, p), out, cv::COLOR_BayerRG2BGR);
        break;
      case ARV_PIXEL_FORMAT_BAYER_GR_8:
        cv::cvtColor(cv::Mat(h, w, CV_8UC1, p), out, cv::COLOR_BayerGB2BGR);
        break;
      case ARV_PIXEL_FORMAT_BAYER_GB_8:
        cv::cvtColor(cv::Mat(h, w, CV_8UC1, p), out, cv::COLOR_BayerGR2BGR);
        break;
      case ARV_PIXEL_FORMAT_RGB_8_PACKED:
        cv::cvtColor(cv::Mat(h, w, CV_8UC3, p), out, cv::COLOR_RGB2BGR);
        break;
      case ARV_PIXEL_FORMAT_BGR_8_PACKED:
        cv::Mat(h, w, CV_8UC3, p).copyTo(out);
        break;
      default:
        why = "unsupported pixel format 0x" + [&] {
          char s[16];
          std::snprintf(s, sizeof s, "%08x", static_cast<unsigned>(pf));
          return std::string(s);
        }();
        return false;
    }
    return true;
  }
};

AravisCamera::AravisCamera(const std::string& device, AravisParams params,
                           std::shared_ptr<Clock> clock, std::string uri)
    : impl_(std::make_unique<Impl>()), uri_(uri.empty() ? "aravis://" + device : uri) {
  params.validate();
  if (device.empty())
    throw InputError("camera URI '" + uri_ + "': expected aravis://ADDRESS-or-ID");
  if (!clock) clock = std::make_shared<SteadyClock>();
  Impl& s = *impl_;
  s.device = device;
  s.params = params;
  s.clock = std::move(clock);
  s.uri = uri_;
  {
    Opened o = s.open();
    std::lock_guard<std::mutex> lock(s.mutex);
    s.adopt(o);
  }
  s.up = true;
  log::info(
      "aravis", "streaming",
      {{"uri", uri_},
       {"size", std::to_string(s.intrinsics.width) + "x" + std::to_string(s.intrinsics.height)},
       {"pixel_format", s.pixel_format}});
}

AravisCamera::~AravisCamera() {
  Impl& s = *impl_;
  s.quitting = true;
  if (s.reconnector.joinable()) s.reconnector.join();
  std::lock_guard<std::mutex> lock(s.mutex);
  s.disconnectSignal();
  closeOpened(s.cam);
  closeOpened(s.pending);
}

GrabStatus AravisCamera::grab(Frame& frame, double timeout_s) {
  Impl& s = *impl_;
  SteadyClock wall;
  while (true) {
    ArvStream* stream = nullptr;
    {
      std::lock_guard<std::mutex> lock(s.mutex);
      if (!s.cam.stream && s.pending.stream) {  // reopened: take it over
        s.adopt(s.pending);
        s.pending = {};
        ++s.reconnects;
        log::info("aravis", "camera reopened", {{"uri", s.uri}});
      }
      if (s.cam.stream &&
          (s.control_lost || s.clock->now() - s.last_frame_t > s.params.lost_timeout_s))
        s.lose(s.control_lost ? "control lost"
                              : "no frame for " + shortNumber(s.params.lost_timeout_s) + " s");
      stream = s.cam.stream;
    }
    const double left = timeout_s - wall.now();
    if (left <= 0) return GrabStatus::Timeout;
    if (!stream) {  // reconnecting: wait a little, never longer than asked
      wall.sleepUntil(wall.now() + std::min(left, 0.02));
      continue;
    }
    const guint64 us = static_cast<guint64>(std::min(left, 0.1) * 1e6);
    ArvBuffer* b = arv_stream_timeout_pop_buffer(stream, us);
    if (!b) continue;  // loop re-checks liveness and the caller's timeout
    std::lock_guard<std::mutex> lock(s.mutex);
    if (s.cam.stream != stream) {  // lost meanwhile (cannot happen: grab is single-threaded)
      g_object_unref(b);
      continue;
    }
    const double now = s.clock->now();
    s.last_frame_t = now;
    const guint64 id = arv_buffer_get_frame_id(b);
    if (s.have_frame_id && id > s.last_frame_id + 1) s.stats.dropped += id - s.last_frame_id - 1;
    if (!s.have_frame_id || id > s.last_frame_id) s.last_frame_id = id;
    s.have_frame_id = true;
    guint64 completed = 0, failures = 0, underruns = 0;
    arv_stream_get_statistics(stream, &completed, &failures, &underruns);
    if (underruns > s.underruns_base) {
      s.stats.dropped += underruns - s.underruns_base;
      s.underruns_base = underruns;
    }
    const ArvBufferStatus status = arv_buffer_get_status(b);
    if (status != ARV_BUFFER_STATUS_SUCCESS) {
      ++s.stats.incomplete;
      log::debug("aravis", "incomplete frame",
                 {{"frame_id", std::to_string(id)}, {"status", std::to_string(status)}});
      arv_stream_push_buffer(stream, b);
      continue;
    }
    std::string why;
    const bool ok = s.convert(b, frame.image, why);
    // Aravis stamps a buffer with the host's real time when its first packet arrives.
    const guint64 arrived_ns = arv_buffer_get_system_timestamp(b);
    arv_stream_push_buffer(stream, b);
    if (ok && arrived_ns > 0) {
      const double ms =
          (static_cast<double>(g_get_real_time()) * 1e3 - static_cast<double>(arrived_ns)) / 1e6;
      if (ms >= 0 && ms < 60000) s.latency_sum_ms += ms, ++s.latency_n;
    }
    if (!ok) {
      ++s.stats.dropped;
      s.stats.last_error = why;
      log::warn("aravis", "frame skipped", {{"uri", s.uri}, {"why", why}});
      continue;
    }
    frame.stamp = now;
    frame.seq = s.seq++;
    frame.source = s.device + "#" + std::to_string(id);
    ++s.stats.received;
    if (!s.up) {
      s.stats.last_error.clear();
      s.setUp(true);
    }
    return GrabStatus::Ok;
  }
}

Intrinsics AravisCamera::intrinsics() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->intrinsics;
}

DeviceStats AravisCamera::stats() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->stats;
}

bool AravisCamera::setLinkCallback(std::function<void(bool)> cb) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->callback = std::move(cb);
  return true;
}

bool AravisCamera::connected() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->cam.stream != nullptr;
}

std::uint64_t AravisCamera::reconnects() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->reconnects;
}

double AravisCamera::meanLatencyMs() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->latency_n ? impl_->latency_sum_ms / static_cast<double>(impl_->latency_n) : -1.0;
}

std::string AravisCamera::pixelFormat() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->pixel_format;
}

}  // namespace sketchnav::drivers
