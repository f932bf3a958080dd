#pragma once
// What `sketchnav ros nav` shows of its work (doc/ros.md "Published"), for rviz and tools:
//   ~image             sensor_msgs/Image bgr8 (image_transport when built with it: also
//                      ~image/compressed), the frame perception examined with its detections
//   ~pose              geometry_msgs/PoseStamped, the estimated pose, odometry frame, every tick
//   ~route             nav_msgs/Path, the sketch's route as currently aligned to odometry
//   ~landmarks         visualization_msgs/MarkerArray, where the sketch puts each landmark
//                      (odometry frame; colour by state), with its id as text
//   /diagnostics       diagnostic_msgs/DiagnosticArray (diagnostic_updater when built with it):
//                      each input's age and limit, the safety stop state and its fault, 1 Hz
// No ROS types here: points are plain numbers in the odometry frame.
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace sketchnav::ros {

struct LandmarkMark {
  std::string id, state;  // state: pending | tracking | passed | missed
  double x = 0, y = 0;    // [m] odometry frame
};

class NavOutputs {
 public:
  /// `odom_frame`: the frame of pose / route / landmarks (REP 105 "odom").
  explicit NavOutputs(const std::string& odom_frame);
  ~NavOutputs();
  /// True when something subscribes to ~image (drawing it costs time otherwise wasted).
  bool wantImage() const;
  void image(const cv::Mat& bgr, double stamp, const std::string& frame_id);
  void pose(double x, double y, double theta, double stamp);
  void route(const std::vector<std::pair<double, double>>& pts, double stamp);
  void landmarks(const std::vector<LandmarkMark>& marks, double stamp);
  /// The route state for /diagnostics ("idle", "running section 2/5", "stopped: ...").
  void status(const std::string& s);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sketchnav::ros
