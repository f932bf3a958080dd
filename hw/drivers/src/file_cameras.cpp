#include "sketchnav/drivers/file_cameras.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <opencv2/videoio/registry.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

#include "sketchnav/core/config.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/image_file.h"
#include "sketchnav/core/log.h"

namespace fs = std::filesystem;

namespace sketchnav::drivers {
namespace {

// "frame2.png" < "frame10.png": compare digit runs by value.
bool naturalLess(const std::string& a, const std::string& b) {
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (std::isdigit(static_cast<unsigned char>(a[i])) &&
        std::isdigit(static_cast<unsigned char>(b[j]))) {
      size_t ie = i, je = j;
      while (ie < a.size() && std::isdigit(static_cast<unsigned char>(a[ie]))) ++ie;
      while (je < b.size() && std::isdigit(static_cast<unsigned char>(b[je]))) ++je;
      std::string na = a.substr(i, ie - i), nb = b.substr(j, je - j);
      na.erase(0, std::min(na.find_first_not_of('0'), na.size()));
      nb.erase(0, std::min(nb.find_first_not_of('0'), nb.size()));
      if (na.size() != nb.size()) return na.size() < nb.size();
      if (na != nb) return na < nb;
      i = ie;
      j = je;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  return a.size() - i < b.size() - j;
}

// Decoded frames go to the pipeline as 8-bit BGR whatever the file held.
cv::Mat toBgr8(const cv::Mat& in) {
  cv::Mat m = in;
  if (m.depth() != CV_8U) {
    double mn, mx;
    cv::minMaxLoc(m.reshape(1), &mn, &mx);
    m.convertTo(m, CV_8U, mx > mn ? 255.0 / (mx - mn) : 1.0, mx > mn ? -mn * 255.0 / (mx - mn) : 0);
  }
  if (m.channels() == 1)
    cv::cvtColor(m, m, cv::COLOR_GRAY2BGR);
  else if (m.channels() == 4)
    cv::cvtColor(m, m, cv::COLOR_BGRA2BGR);
  return m;
}
}  // namespace

void FolderCameraParams::validate() const {
  require(std::isfinite(fps) && fps > 0 && fps <= 1000, "camera.folder.fps",
          "must be in (0, 1000] Hz");
  require(hfov_deg > 1 && hfov_deg < 179, "camera.folder.hfov_deg", "must be in (1, 179) degrees");
}

std::vector<std::string> listImages(const std::string& dir) {
  std::error_code ec;
  if (!fs::exists(dir, ec)) throw InputError("image folder '" + dir + "' does not exist");
  if (!fs::is_directory(dir, ec)) throw InputError("'" + dir + "' is not a directory");
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.is_regular_file() && isImageFileName(e.path().string()))
      names.push_back(e.path().filename().string());
  if (ec) throw InputError("image folder '" + dir + "' cannot be read: " + ec.message());
  std::sort(names.begin(), names.end(), naturalLess);
  std::vector<std::string> out;
  for (const auto& n : names) out.push_back((fs::path(dir) / n).string());
  return out;
}

FolderCamera::FolderCamera(const std::string& dir, FolderCameraParams params, std::string uri)
    : files_(listImages(dir)), params_(params), uri_(uri.empty() ? "folder://" + dir : uri) {
  params_.validate();
  if (files_.empty()) throw InputError("image folder '" + dir + "' holds no images");
  // Intrinsics come from the first readable frame's size.
  for (const auto& f : files_) {
    try {
      const cv::Mat m = readImageFile(f, "frame", ImageMode::Unchanged);
      intrinsics_ = Intrinsics::fromFov(m.cols, m.rows, params_.hfov_deg * M_PI / 180.0);
      return;
    } catch (const InputError&) {
      // grab() skips it with a warning too
    }
  }
  throw InputError("image folder '" + dir + "': none of its " + std::to_string(files_.size()) +
                   " images can be decoded");
}

GrabStatus FolderCamera::grab(Frame& frame, double) {
  while (true) {
    if (next_ >= files_.size()) {
      if (!params_.loop) return GrabStatus::EndOfStream;
      next_ = 0;
    }
    const std::string& path = files_[next_++];
    cv::Mat m;
    try {
      // Regular files only, the pixel bound checked on the header before decoding.
      m = readImageFile(path, "frame", ImageMode::Unchanged);
    } catch (const InputError& e) {
      ++stats_.dropped;
      stats_.last_error = e.what();
      log::warn("camera.folder", "skipped unreadable frame", {{"file", path}, {"error", e.what()}});
      continue;
    }
    frame.image = toBgr8(m);
    frame.seq = seq_++;
    frame.stamp = static_cast<double>(frame.seq) / params_.fps;
    frame.source = path;
    ++stats_.received;
    return GrabStatus::Ok;
  }
}

struct VideoCamera::Impl {
  cv::VideoCapture cap;
};

namespace {
// A file through the backends that read files, in OpenCV's order, except gPhoto2: with
// CAP_ANY, a file FFmpeg cannot read goes on to gPhoto2, which looks for still cameras on the
// USB bus (seconds on a busy bus, and libgphoto2 leaks libusb's device list each time:
// LeakSanitizer, doc/reliability.md). A video file is never a USB still camera.
bool openFile(cv::VideoCapture& cap, const std::string& path) {
  for (const auto api : cv::videoio_registry::getStreamBackends())
    if (api != cv::CAP_GPHOTO2 && cap.open(path, api)) return true;
  return false;
}
}  // namespace

VideoCamera::VideoCamera(const std::string& source, double hfov_deg, std::string uri)
    : impl_(std::make_unique<Impl>()), uri_(uri.empty() ? "video://" + source : uri) {
  is_device_ = !source.empty() && std::all_of(source.begin(), source.end(),
                                              [](unsigned char c) { return std::isdigit(c); });
  if (is_device_) {
    if (!impl_->cap.open(std::stoi(source)))
      throw InputError("video device " + source + " cannot be opened");
  } else {
    if (!fs::exists(source)) throw InputError("video file '" + source + "' does not exist");
    if (!openFile(impl_->cap, source))
      throw InputError("video file '" + source + "' cannot be opened");
  }
  int w = static_cast<int>(impl_->cap.get(cv::CAP_PROP_FRAME_WIDTH));
  int h = static_cast<int>(impl_->cap.get(cv::CAP_PROP_FRAME_HEIGHT));
  if (w <= 0 || h <= 0) {
    w = 640;
    h = 480;
  }
  intrinsics_ = Intrinsics::fromFov(w, h, hfov_deg * M_PI / 180.0);
}

VideoCamera::~VideoCamera() = default;

GrabStatus VideoCamera::grab(Frame& frame, double) {
  // A few consecutive undecodable frames are skipped; a run of them ends a file.
  for (int attempt = 0; attempt < 8; ++attempt) {
    cv::Mat m;
    bool ok = false;
    try {
      ok = impl_->cap.read(m);
    } catch (const cv::Exception& e) {
      ok = false;
      stats_.last_error = e.what();
    }
    if (ok && !m.empty()) {
      frame.image = toBgr8(m);
      frame.seq = seq_++;
      const double ms = impl_->cap.get(cv::CAP_PROP_POS_MSEC);
      frame.stamp = ms > 0 ? ms / 1000.0 : static_cast<double>(frame.seq) / 30.0;
      frame.source = uri_ + "#" + std::to_string(frame.seq);
      ++stats_.received;
      return GrabStatus::Ok;
    }
    if (!is_device_) {
      const double pos = impl_->cap.get(cv::CAP_PROP_POS_FRAMES);
      const double count = impl_->cap.get(cv::CAP_PROP_FRAME_COUNT);
      if (count <= 0 || pos >= count) return GrabStatus::EndOfStream;
    }
    ++stats_.dropped;
    log::warn("camera.video", "skipped unreadable frame", {{"uri", uri_}});
  }
  if (is_device_) {
    stats_.last_error = "device delivers no frames";
    return GrabStatus::Timeout;
  }
  return GrabStatus::EndOfStream;
}

}  // namespace sketchnav::drivers
