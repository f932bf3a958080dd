#pragma once
// Cameras over recorded images, through OpenCV:
//   folder:///path/to/frames[?fps=10&loop=0&hfov_deg=60]   images sorted by name (natural order)
//   video:///path/to/clip.mp4[?hfov_deg=60]                 a video file
//   video://0                                               a USB / V4L2 device by index
// Unreadable or corrupt frames are skipped with a warning and counted as dropped; a missing
// path or a folder without images is an InputError naming the path.
#include <memory>
#include <string>
#include <vector>

#include "sketchnav/core/uri.h"
#include "sketchnav/drivers/hw_names.h"

namespace sketchnav::drivers {

struct FolderCameraParams {
  double fps = 10.0;       // [Hz] stamps are seq / fps when no clock is given
  bool loop = false;       // restart at the first image after the last
  double hfov_deg = 60.0;  // [deg] horizontal field of view for the intrinsics
  template <class B>
  void bind(B& b) {
    b("fps", fps);
    b("loop", loop);
    b("hfov_deg", hfov_deg);
  }
  void validate() const;
};

class FolderCamera final : public Camera {
 public:
  FolderCamera(const std::string& dir, FolderCameraParams params, std::string uri = {});
  GrabStatus grab(Frame& frame, double timeout_s = 1.0) override;
  Intrinsics intrinsics() const override { return intrinsics_; }
  DeviceStats stats() const override { return stats_; }
  std::string uri() const override { return uri_; }
  const std::vector<std::string>& files() const { return files_; }

 private:
  std::vector<std::string> files_;
  FolderCameraParams params_;
  std::string uri_;
  size_t next_ = 0;
  std::uint64_t seq_ = 0;
  Intrinsics intrinsics_;
  DeviceStats stats_;
};

class VideoCamera final : public Camera {
 public:
  /// `source` is a file path or a device index ("0").
  VideoCamera(const std::string& source, double hfov_deg, std::string uri = {});
  ~VideoCamera() override;
  GrabStatus grab(Frame& frame, double timeout_s = 1.0) override;
  Intrinsics intrinsics() const override { return intrinsics_; }
  DeviceStats stats() const override { return stats_; }
  std::string uri() const override { return uri_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::string uri_;
  bool is_device_ = false;
  std::uint64_t seq_ = 0;
  Intrinsics intrinsics_;
  DeviceStats stats_;
};

/// Image files (sketchnav::isImageFileName) directly inside `dir`, in natural order ("frame2"
/// before "frame10").
std::vector<std::string> listImages(const std::string& dir);

}  // namespace sketchnav::drivers
