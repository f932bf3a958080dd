// The route action and its topic twins (route_server.h).
#include <actionlib/server/simple_action_server.h>
#include <ros/ros.h>
#include <std_msgs/Empty.h>
#include <std_msgs/String.h>

#include <sketchnav_msgs/NavigateSketchAction.h>

#include <condition_variable>
#include <deque>
#include <mutex>

#include "internal.h"
#include "sketchnav/core/log.h"
#include "sketchnav/ros/route_server.h"

namespace sketchnav::ros {

using Server = actionlib::SimpleActionServer<sketchnav_msgs::NavigateSketchAction>;

struct RouteServer::Impl {
  ::ros::NodeHandle pnh{"~"};
  std::unique_ptr<Server> server;
  ::ros::Subscriber start_sub, cancel_sub;
  mutable std::mutex m;
  std::condition_variable cv;
  std::deque<RouteGoal> topic_goals;  // from ~start
  bool action_goal_waiting = false;   // the action has a new goal (goal callback)
  bool active = false, active_is_action = false;
  bool cancel = false;  // the active goal: cancelled or preempted

  void onStart(const std_msgs::StringConstPtr& m) {
    RouteGoal g;
    g.source = "topic";
    const std::string& d = m->data;
    if (!d.empty() && d.front() == '{') {
      try {
        const Json j = Json::parse(d);
        g.sketch = j.value("sketch", "");
        g.model = j.value("model", "");
      } catch (const std::exception& e) {
        log::error("ros", "~start: not a sketch path nor JSON {\"sketch\": ...}: " +
                              std::string(e.what()));
        return;
      }
    } else {
      g.sketch = d;
    }
    if (g.sketch.empty()) {
      log::error("ros", "~start: no sketch given (a path, or JSON {\"sketch\": ...}): ignored");
      return;
    }
    std::lock_guard<std::mutex> l(this->m);
    if (active) {  // preempts the running route, as an action goal does
      cancel = true;
      hold("~start: a new route preempts the running one");
    }
    topic_goals.push_back(g);
    cv.notify_all();
  }
  void onCancel(const std_msgs::EmptyConstPtr&) {
    std::lock_guard<std::mutex> l(m);
    topic_goals.clear();
    if (active) {
      cancel = true;
      hold("~cancel: the route is stopped");
    }
  }
  void onGoal() {  // actionlib: a new goal arrived (the server's lock is held)
    std::lock_guard<std::mutex> l(m);
    action_goal_waiting = true;
    if (active) {
      cancel = true;
      hold("a new action goal preempts the running route");
    }
    cv.notify_all();
  }
  void onPreempt() {  // actionlib: the active goal is cancelled (or a new one preempts it)
    std::lock_guard<std::mutex> l(m);
    if (active && active_is_action) {
      cancel = true;
      hold("the action goal was cancelled");
    }
  }
};

RouteServer::RouteServer(const std::string& name) : impl_(std::make_unique<Impl>()) {
  detail::nodeHandle();  // the node is up
  Impl& I = *impl_;
  I.server = std::make_unique<Server>(I.pnh, name, false);
  I.server->registerGoalCallback([&I] { I.onGoal(); });
  I.server->registerPreemptCallback([&I] { I.onPreempt(); });
  I.server->start();
  I.start_sub = I.pnh.subscribe("start", 5, &Impl::onStart, &I);
  I.cancel_sub = I.pnh.subscribe("cancel", 5, &Impl::onCancel, &I);
  log::info("ros", "waiting for goals",
            {{"action", I.pnh.resolveName(name)},
             {"start", I.start_sub.getTopic()},
             {"cancel", I.cancel_sub.getTopic()}});
}

RouteServer::~RouteServer() {
  Impl& I = *impl_;
  I.start_sub.shutdown();
  I.cancel_sub.shutdown();
  if (I.server && I.server->isActive()) I.server->setAborted({}, "node shutting down");
  I.server->shutdown();
}

bool RouteServer::waitGoal(RouteGoal& goal, double timeout_s) {
  Impl& I = *impl_;
  const double t0 = detail::wallNow();
  while (ok() && detail::wallNow() - t0 < timeout_s) {
    {
      std::unique_lock<std::mutex> l(I.m);
      I.cv.wait_for(l, std::chrono::milliseconds(20));
      if (I.action_goal_waiting) {
        I.action_goal_waiting = false;
        l.unlock();
        if (!I.server->isNewGoalAvailable()) continue;  // cancelled before it was taken
        const auto g = I.server->acceptNewGoal();
        if (!g) continue;
        l.lock();
        goal = RouteGoal{g->sketch, g->model, "action"};
        I.active = true;
        I.active_is_action = true;
        I.cancel = false;
        return true;
      }
      if (!I.topic_goals.empty()) {
        goal = I.topic_goals.back();  // the latest wins
        I.topic_goals.clear();
        I.active = true;
        I.active_is_action = false;
        I.cancel = false;
        return true;
      }
    }
  }
  return false;
}

bool RouteServer::cancelRequested() const {
  std::lock_guard<std::mutex> l(impl_->m);
  return impl_->cancel;
}

void RouteServer::feedback(const RouteFeedback& f) {
  Impl& I = *impl_;
  {
    std::lock_guard<std::mutex> l(I.m);
    if (!I.active || !I.active_is_action) return;
  }
  if (!I.server->isActive()) return;
  sketchnav_msgs::NavigateSketchFeedback fb;
  fb.section = f.section;
  fb.sections = f.sections;
  fb.distance_left_m = f.distance_left_m;
  fb.mode = f.mode;
  fb.landmark = f.landmark;
  I.server->publishFeedback(fb);
}

void RouteServer::finish(const RouteResult& r) {
  Impl& I = *impl_;
  bool is_action, cancelled;
  {
    std::lock_guard<std::mutex> l(I.m);
    is_action = I.active && I.active_is_action;
    cancelled = I.cancel;
    I.active = false;
    I.cancel = false;
  }
  if (!is_action || !I.server->isActive()) return;
  sketchnav_msgs::NavigateSketchResult res;
  res.success = r.success;
  res.failure = r.failure;
  res.reason = r.reason;
  res.sections_done = r.sections_done;
  res.sections = r.sections;
  res.summary_json = r.summary.is_null() ? "" : r.summary.dump();
  if (r.success)
    I.server->setSucceeded(res, r.reason);
  else if (cancelled && I.server->isPreemptRequested())
    I.server->setPreempted(res, r.reason);
  else
    I.server->setAborted(res, r.reason);
}

}  // namespace sketchnav::ros
