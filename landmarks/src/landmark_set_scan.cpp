#include <algorithm>
#include <cctype>
#include <filesystem>
#include <map>
#include <set>

#include <sys/stat.h>

#include "sketchnav/core/error.h"
#include "sketchnav/core/image_file.h"
#include "sketchnav/core/log.h"
#include "sketchnav/landmarks/landmark_set.h"

namespace fs = std::filesystem;

namespace sketchnav::landmarks {

std::string classOfImage(const std::string& path) {
  return fs::path(path).parent_path().filename().string();
}

LandmarkSet scanLandmarkSet(const std::string& root) {
  std::error_code ec;
  if (!fs::is_directory(root, ec))
    throw InputError(root +
                     ": landmark set folder not found (expected a folder of class "
                     "folders)");
  LandmarkSet set;
  set.root = fs::canonical(root).string();
  std::map<std::string, std::vector<std::string>> classes;
  // Walk every folder; a folder without sub-folders is a class. Each directory (by device and
  // inode, so symlinks are followed but `A/loop -> ..` is not walked again) is visited once.
  std::set<std::pair<dev_t, ino_t>> visited;
  auto firstVisit = [&visited](const fs::path& p) {
    struct stat st {};
    if (::stat(p.c_str(), &st) != 0) return false;
    return visited.insert({st.st_dev, st.st_ino}).second;
  };
  firstVisit(set.root);
  std::vector<fs::path> stack{fs::path(set.root)};
  while (!stack.empty()) {
    const fs::path dir = stack.back();
    stack.pop_back();
    std::vector<fs::path> subdirs, files;
    for (const auto& e :
         fs::directory_iterator(dir, fs::directory_options::skip_permission_denied, ec)) {
      if (e.is_directory(ec)) {
        if (firstVisit(e.path()))
          subdirs.push_back(e.path());
        else
          set.skipped.push_back(e.path().string() + ": folder already visited (symlink loop?)");
      } else if (e.is_regular_file(ec))
        files.push_back(e.path());
    }
    if (!subdirs.empty()) {
      for (const auto& f : files)
        if (isImageFileName(f.string()))
          set.skipped.push_back(f.string() + ": photo outside a class (leaf) folder");
      stack.insert(stack.end(), subdirs.begin(), subdirs.end());
      continue;
    }
    // (A root without sub-folders is itself one class, named after the folder.)
    std::vector<std::string> photos;
    for (const auto& f : files) {
      if (isImageFileName(f.string()))
        photos.push_back(f.string());
      else
        set.skipped.push_back(f.string() + ": not a photo");
    }
    if (photos.empty()) {
      set.skipped.push_back(dir.string() + ": class folder holds no photos");
      continue;
    }
    auto& dst = classes[dir.filename().string()];
    dst.insert(dst.end(), photos.begin(), photos.end());
  }
  for (auto& [name, photos] : classes) {
    std::sort(photos.begin(), photos.end());
    set.classes.push_back({name, photos});
  }
  for (const auto& s : set.skipped) log::warn("landmarks", "skipped", {{"what", s}});
  if (set.classes.empty())
    throw InputError(root + ": no class folder with photos (expected <root>/<class>/*.jpg)");
  return set;
}

}  // namespace sketchnav::landmarks
