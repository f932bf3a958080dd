#include "entry_points.h"

namespace sketchnav::fuzz {

EntryPoint byName(const std::string& name) {
  if (name == "sketch") return &sketch;
  if (name == "world") return &world;
  if (name == "config") return &config;
  if (name == "model") return &model;
  if (name == "protocol") return &baseProtocol;
  if (name == "image") return &image;
  if (name == "voc") return &voc;
  if (name == "truth") return &truth;
  if (name == "webui") return &webui;
  if (name == "rawlog") return &rawlog;
  if (name == "protocol_sealed") return &baseProtocolSealed;
  if (name == "model_sealed") return &modelSealed;
  return nullptr;
}

}  // namespace sketchnav::fuzz
