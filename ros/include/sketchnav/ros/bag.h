#pragma once
// Cameras over recorded ROS bags (no master needed):
//   bag:///abs/run.bag[?topic=/camera/image_raw&info=/camera/camera_info&hfov_deg=60]
// sensor_msgs/Image (any encoding cv_bridge turns into bgr8) or sensor_msgs/CompressedImage
// (jpeg / png) messages in bag order; stamps are the messages' header stamps (the bag's
// receive time when zero) relative to the first frame. Without `topic` the bag's only image
// topic is used. Intrinsics from the first CameraInfo on `info` (default: camera_info beside
// the image topic), else from hfov_deg. A frame that cannot be decoded is skipped with a
// warning and counted as dropped; the end of the bag is EndOfStream.
namespace sketchnav::ros {

/// Registers the bag:// camera with hw::Registry. Idempotent.
void registerBagDriver();

}  // namespace sketchnav::ros
