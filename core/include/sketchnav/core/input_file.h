#pragma once
// The rules every loader and writer applies to the paths it is given (doc/reliability.md):
// inputs are regular files (a FIFO, device or directory would block or make no sense), outputs
// go to regular files or new files in folders that already exist, and error messages quote user
// values only in part.
#include <cstdint>
#include <string>

namespace sketchnav {

/// Throws InputError "<what> '<path>': ..." unless `path` names an existing regular file
/// (symlinks are followed). Call it before opening any input file.
void requireRegularFile(const std::string& path, const std::string& what);

/// requireRegularFile() plus a size bound: throws InputError when the file is larger than
/// `max_bytes`. Returns the size.
std::uint64_t requireRegularFileUpTo(const std::string& path, const std::string& what,
                                     std::uint64_t max_bytes);

/// Reads a whole regular file of at most `max_bytes` (binary); InputError naming the file on
/// any problem.
std::string readInputFile(const std::string& path, const std::string& what,
                          std::uint64_t max_bytes);

/// Throws InputError naming the path when it cannot be an output file: it exists and is not a
/// regular file (e.g. /dev/full, a FIFO, a directory), or its parent folder does not exist.
void requireOutputFile(const std::string& path, const std::string& what);

/// Writes `data` to `path` whole or not at all: requireOutputFile(), then a temporary file
/// beside it (`<path>.tmp.<pid>`) renamed over `path`, so a reader, or a process killed
/// mid-write (kill -9), never leaves a half-written file under `path`. RuntimeError naming the
/// file when it cannot be written.
void writeFileAtomically(const std::string& path, const std::string& data, const std::string& what);

/// `s` cut to its first `max_chars` bytes plus "…" when longer, for quoting user values in
/// one-line error messages.
std::string clipForMessage(const std::string& s, std::size_t max_chars = 80);

}  // namespace sketchnav
