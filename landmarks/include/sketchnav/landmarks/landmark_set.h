#pragma once
// A landmark set on disk: a folder of class folders. A class is a leaf folder (no
// sub-folders) holding photos of one object; nested folders are allowed and the class name is
// the leaf's name (grocery-packages/train/Juice/Bravo-Apple-Juice/ -> "Bravo-Apple-Juice").
// Two leaves with the same name are one class.
#include <string>
#include <vector>

namespace sketchnav::landmarks {

struct LandmarkClass {
  std::string name;
  std::vector<std::string> photos;  // absolute paths, sorted
};

struct LandmarkSet {
  std::string root;
  std::vector<LandmarkClass> classes;  // sorted by name; only classes with >= 1 photo
  std::vector<std::string> skipped;    // files / folders ignored, with the reason
};

/// Scans `root`. Files that are not images (sketchnav::isImageFileName) and empty leaf folders are
/// listed in `skipped` (and logged); whether a photo decodes is checked later, when it is read.
/// Throws InputError naming `root` when it is not a folder or holds no photos at all. A root
/// without sub-folders is one class named after it.
LandmarkSet scanLandmarkSet(const std::string& root);

/// Leaf class name of an image path inside a landmark set (its parent folder's name).
std::string classOfImage(const std::string& path);

}  // namespace sketchnav::landmarks
