#include "sketchnav/core/input_file.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "sketchnav/core/error.h"

namespace sketchnav {
namespace {
std::string kindOf(mode_t m) {
  if (S_ISDIR(m)) return "a directory";
  if (S_ISFIFO(m)) return "a FIFO";
  if (S_ISCHR(m)) return "a character device";
  if (S_ISBLK(m)) return "a block device";
  if (S_ISSOCK(m)) return "a socket";
  return "not a regular file";
}

std::string quoted(const std::string& what, const std::string& path) {
  return what + " '" + clipForMessage(path, 200) + "'";
}
}  // namespace

std::string clipForMessage(const std::string& s, std::size_t max_chars) {
  if (s.size() <= max_chars) return s;
  std::size_t cut = max_chars;
  // Do not cut a UTF-8 sequence in half.
  while (cut > 0 && (static_cast<unsigned char>(s[cut]) & 0xC0) == 0x80) --cut;
  return s.substr(0, cut) + "\xE2\x80\xA6";  // "…"
}

void requireRegularFile(const std::string& path, const std::string& what) {
  requireRegularFileUpTo(path, what, UINT64_MAX);
}

std::uint64_t requireRegularFileUpTo(const std::string& path, const std::string& what,
                                     std::uint64_t max_bytes) {
  struct stat st {};
  if (path.empty()) throw InputError(what + ": empty file name");
  if (::stat(path.c_str(), &st) != 0)
    throw InputError(quoted(what, path) + " cannot be opened (" + std::strerror(errno) + ")");
  if (!S_ISREG(st.st_mode))
    throw InputError(quoted(what, path) + ": is " + kindOf(st.st_mode) +
                     ", expected a regular file");
  const auto size = static_cast<std::uint64_t>(st.st_size);
  if (size > max_bytes)
    throw InputError(quoted(what, path) + ": too large (" + std::to_string(size) + " bytes > " +
                     std::to_string(max_bytes) + ")");
  return size;
}

std::string readInputFile(const std::string& path, const std::string& what,
                          std::uint64_t max_bytes) {
  requireRegularFileUpTo(path, what, max_bytes);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(quoted(what, path) + ": cannot open");
  std::string data;
  char buf[65536];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    data.append(buf, static_cast<std::size_t>(in.gcount()));
    // The file may have grown since stat(): never read more than the bound.
    if (data.size() > max_bytes)
      throw InputError(quoted(what, path) + ": too large (> " + std::to_string(max_bytes) +
                       " bytes)");
  }
  if (in.bad()) throw InputError(quoted(what, path) + ": read error");
  return data;
}

void requireOutputFile(const std::string& path, const std::string& what) {
  if (path.empty()) throw InputError(what + ": empty file name");
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) {
    if (!S_ISREG(st.st_mode))
      throw InputError(quoted(what, path) + ": is " + kindOf(st.st_mode) +
                       "; outputs are written only to regular files");
    return;
  }
  std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (parent.empty()) return;
  std::error_code ec;
  if (!std::filesystem::is_directory(parent, ec))
    throw InputError(quoted(what, path) + ": folder '" + clipForMessage(parent.string(), 200) +
                     "' does not exist");
}

void writeFileAtomically(const std::string& path, const std::string& data,
                         const std::string& what) {
  // The rename below would replace a device node or FIFO: refused first.
  requireOutputFile(path, what);
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  std::error_code ec;
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw RuntimeError(quoted(what, path) + ": cannot write " + tmp);
    out.write(data.data(), static_cast<std::streamsize>(data.size()));
    out.close();
    if (!out) {
      std::filesystem::remove(tmp, ec);
      throw RuntimeError(quoted(what, path) + ": writing failed (disk full?)");
    }
  }
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    const std::string why = ec.message();
    std::filesystem::remove(tmp, ec);
    throw RuntimeError(quoted(what, path) + ": cannot move it into place: " + why);
  }
}

}  // namespace sketchnav
