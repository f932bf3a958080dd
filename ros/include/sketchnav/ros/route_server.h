#pragma once
// Starting and cancelling routes through ROS (doc/ros.md "The action"): an actionlib action
// server `~route` (sketchnav_msgs/NavigateSketchAction: goal sketch + model, feedback section
// k/n and distance left, result success / failure code / reason), and for `rostopic`-only use
// `~start` (std_msgs/String: a sketch path, or JSON {"sketch": ..., "model": ...}) and
// `~cancel` (std_msgs/Empty). One route at a time: a new goal while one runs preempts it.
// Everything here runs on the thread that calls it; ROS callbacks only queue.
#include <memory>
#include <string>

#include "sketchnav/core/config.h"

namespace sketchnav::ros {

struct RouteGoal {
  std::string sketch, model;
  std::string source;  // "action" or "topic"
};

struct RouteFeedback {
  int section = 0;  // 1-based (sections + 1 once the last is done)
  int sections = 0;
  double distance_left_m = 0;  // [m] along the remaining route, odometry frame
  std::string mode, landmark;
};

struct RouteResult {
  bool success = false;
  std::string failure;  // "" on success, else a code (summary.json's "failure", "cancelled", "error")
  std::string reason;
  int sections_done = 0, sections = 0;
  Json summary;  // the run summary (may be null for a goal that never started)
};

class RouteServer {
 public:
  /// Advertises the action `~<name>` and the topics `~start`, `~cancel` (the node is up).
  explicit RouteServer(const std::string& name = "route");
  ~RouteServer();
  /// Waits up to timeout_s (wall) for a goal (action or topic) and makes it the active one.
  /// False on timeout or when the node is shutting down.
  bool waitGoal(RouteGoal& goal, double timeout_s);
  /// True when the active goal was cancelled (action cancel, ~cancel) or preempted by a new one.
  bool cancelRequested() const;
  void feedback(const RouteFeedback& f);
  /// Ends the active goal: succeeded, preempted (when cancelRequested()) or aborted.
  void finish(const RouteResult& r);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sketchnav::ros
