#pragma once
// The parsers' fuzzing entry points, shared by the libFuzzer harnesses (fuzz_*.cpp, preset
// `fuzz`) and the normal regression test that replays fuzz/regressions/ and the seeds
// (test_fuzz_corpus). Each returns normally for input that is accepted or refused with an
// InputError; anything else (a crash, another exception, a sanitizer report) is a finding.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <string>

#include "sketchnav/core/error.h"

namespace sketchnav::fuzz {

/// The input bytes as a string.
inline std::string text(const std::uint8_t* d, std::size_t n) {
  return std::string(reinterpret_cast<const char*>(d), n);
}

/// For parsers that read files: this process's scratch file for `name`, in /dev/shm when it is
/// writable (cheap), else /tmp. Callers keep it in a static and rewrite it per input.
inline std::string scratchPath(const std::string& name, const std::string& ext) {
  const std::string dir = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
  return dir + "/sketchnav-fuzz-" + name + "-" + std::to_string(::getpid()) + ext;
}

/// Replaces the file at `path` with the input bytes.
inline void writeInput(const std::string& path, const std::uint8_t* d, std::size_t n) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(d), static_cast<std::streamsize>(n));
}

/// Runs `f`; an InputError is the promised outcome for bad input, so it is swallowed, while any
/// other exception (or a crash) reaches the fuzzer as a finding.
template <class F>
void refusedIsFine(F&& f) {
  try {
    f();
  } catch (const InputError&) {
  }
}

void sketch(const std::uint8_t* data, std::size_t size);
void world(const std::uint8_t* data, std::size_t size);
void config(const std::uint8_t* data, std::size_t size);
void model(const std::uint8_t* data, std::size_t size);
void baseProtocol(const std::uint8_t* data, std::size_t size);
void image(const std::uint8_t* data, std::size_t size);
void voc(const std::uint8_t* data, std::size_t size);
void truth(const std::uint8_t* data, std::size_t size);
void webui(const std::uint8_t* data, std::size_t size);
void rawlog(const std::uint8_t* data, std::size_t size);
/// Re-sealed (entry_sealed.cpp): length and checksum fixed up, then the plain entry point.
void baseProtocolSealed(const std::uint8_t* data, std::size_t size);
void modelSealed(const std::uint8_t* data, std::size_t size);

/// The entry point named "sketch", "world", "config", "model", "protocol", "image", "voc",
/// "truth", "webui", "rawlog", "protocol_sealed" or "model_sealed"; nullptr if none.
using EntryPoint = void (*)(const std::uint8_t*, std::size_t);
EntryPoint byName(const std::string& name);

}  // namespace sketchnav::fuzz
