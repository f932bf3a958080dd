#include "sketchnav/hw/gated_base.h"

#include "sketchnav/core/log.h"

namespace sketchnav::hw {

std::unique_ptr<Base> stopBaseWhileCameraIsLost(std::unique_ptr<Base> base, Camera& camera) {
  auto gated = std::make_unique<GatedBase>(std::move(base));
  GatedBase* gate = gated.get();
  const std::string uri = camera.uri();
  camera.setLinkCallback([gate, uri](bool up) {
    if (up) {
      log::info("camera", "frames flow again: motion allowed", {{"camera", uri}});
      gate->setOpen(true);
    } else {
      log::warn("camera", "camera lost: base stopped, motion blocked until frames flow again",
                {{"camera", uri}});
      gate->setOpen(false, "camera lost (" + uri + "): motion blocked until frames flow again");
    }
  });
  return gated;
}

}  // namespace sketchnav::hw
