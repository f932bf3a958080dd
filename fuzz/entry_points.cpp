#include "entry_points.h"

namespace sketchnav::fuzz {

EntryPoint byName(const std::string& name) {
  if (name == "sketch") return &sketch;
  if (name == "world") return &world;
  if (name == "config") return &config;
  if (name == "model") return &model;
  if (name == "protocol") return &baseProtocol;
  if (name == "image") return &image;
  return nullptr;
}

}  // namespace sketchnav::fuzz
