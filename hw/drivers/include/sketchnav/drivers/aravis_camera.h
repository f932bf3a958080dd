#pragma once
// GenICam cameras through Aravis 0.8:
//   aravis://192.168.1.10[?pixel_format=BayerRG8&width=1280&height=960&fps=15&exposure_us=8000
//                         &gain_db=6&buffers=8&packet_size=1500&resend=1&hfov_deg=60]
//   aravis://Fake_1          Aravis's in-process fake camera (serial "1"), no network at all
//   aravis://SOME-DEVICE-ID  any other Aravis device id (GigE/USB3 by id: may use discovery)
// A dotted-quad address opens that GigE Vision device directly (unicast GVCP, no broadcast
// discovery). Settings left at 0 / empty keep the camera's own value.
//
// Frames are converted to 8-bit BGR (Mono8/16, Bayer xx8, RGB8, BGR8) and stamped with the
// device's Clock when popped. Incomplete frames (missing packets, timeouts) are counted in
// stats().incomplete and skipped; frames the camera sent but no buffer was free for (or whose
// frame id skipped) count as dropped. When the camera goes away (control lost, or no frame
// for `lost_timeout_s`) it is reopened every `reconnect_period_s`; the link callback is told
// "lost" at once and "back" when frames flow again, so the owner can stop the robot meanwhile.
#include <functional>
#include <memory>
#include <string>

#include "sketchnav/core/uri.h"
#include "sketchnav/drivers/hw_names.h"

namespace sketchnav::drivers {

struct AravisParams {
  std::string pixel_format;         // GenICam PixelFormat name ("Mono8", "BayerRG8"); empty: keep
  int width = 0;                    // [px] region of interest; 0: keep
  int height = 0;                   // [px]
  double fps = 0.0;                 // [Hz] acquisition frame rate; 0: keep
  double exposure_us = 0.0;         // [us] exposure time; 0: keep (or the camera's auto)
  double gain_db = -1.0;            // [dB]; < 0: keep
  int buffers = 8;                  // stream buffer pool size
  int packet_size = 0;              // [bytes] GigE packet size; 0: keep the camera's
  bool resend = true;               // GigE: ask the camera to resend lost packets
  double hfov_deg = 60.0;           // [deg] horizontal field of view for the intrinsics
  double lost_timeout_s = 3.0;      // [s] no frame for this long while streaming = lost
  double reconnect_period_s = 0.5;  // [s] between reopening attempts
  template <class B>
  void bind(B& b) {
    b("pixel_format", pixel_format);
    b("width", width);
    b("height", height);
    b("fps", fps);
    b("exposure_us", exposure_us);
    b("gain_db", gain_db);
    b("buffers", buffers);
    b("packet_size", packet_size);
    b("resend", resend);
    b("hfov_deg", hfov_deg);
    b("lost_timeout_s", lost_timeout_s);
    b("reconnect_period_s", reconnect_period_s);
  }
  void validate() const;
  /// Overrides fields from URI query parameters of the same names.
  void applyUri(const Uri& uri);
};

class AravisCamera final : public Camera {
 public:
  /// Opens and configures the camera and starts streaming. Throws RuntimeError naming the
  /// device when it cannot be opened, InputError when a setting is refused by the camera.
  AravisCamera(const std::string& device, AravisParams params, std::shared_ptr<Clock> clock,
               std::string uri = {});
  ~AravisCamera() override;

  GrabStatus grab(Frame& frame, double timeout_s = 1.0) override;
  Intrinsics intrinsics() const override;
  DeviceStats stats() const override;
  std::string uri() const override { return uri_; }

  /// Called with false when the camera is lost (no frame for `lost_timeout_s`, or the device
  /// gone) and true when frames flow again, from the thread calling grab(). `sketchnav run`
  /// wires it to "stop the base / allow motion" (hw::stopBaseWhileCameraIsLost). True.
  bool setLinkCallback(std::function<void(bool up)> cb) override;
  bool connected() const;
  std::uint64_t reconnects() const;
  std::string pixelFormat() const;  // what the camera streams
  /// Mean time from a frame's first packet reaching the host to grab() returning it [ms]
  /// (transfer + queueing); -1 before the first frame.
  double meanLatencyMs() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::string uri_;
};

}  // namespace sketchnav::drivers
