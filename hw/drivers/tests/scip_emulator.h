#pragma once
// A Hokuyo laser scanner on loopback TCP, speaking SCIP 2.0 (the protocol of URG/UTM scanners
// over Ethernet), that streams given scans. It lets MRPT's CHokuyoURG driver run unmodified
// against recorded real data. Test-only: one client, the commands MRPT sends (QT, SCIP2.0,
// BM, HS, PP, VV, MD/ME, CR), no error paths.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <string>
#include <thread>
#include <vector>

namespace sketchnav::test {

class ScipEmulator {
 public:
  /// `scans_mm`: the ranges of each scan in millimetres (0 = no echo), all the same length;
  /// step 0 of the device is at -aperture/2 (SCIP counts steps counter-clockwise).
  ScipEmulator(std::vector<std::vector<int>> scans_mm, int steps_per_rev, int max_range_mm,
               double period_s)
      : scans_(std::move(scans_mm)), ares_(steps_per_rev), dmax_(max_range_mm), period_(period_s) {
    listen_ = ::socket(AF_INET, SOCK_STREAM, 0);
    int one = 1;
    ::setsockopt(listen_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::bind(listen_, reinterpret_cast<sockaddr*>(&a), sizeof a);
    ::listen(listen_, 1);
    socklen_t len = sizeof a;
    ::getsockname(listen_, reinterpret_cast<sockaddr*>(&a), &len);
    port_ = ntohs(a.sin_port);
    thread_ = std::thread([this] { run(); });
  }
  ~ScipEmulator() {
    quit_ = true;
    if (thread_.joinable()) thread_.join();
    ::close(listen_);
  }
  int port() const { return port_; }
  int scansSent() const { return sent_; }

  /// SCIP's check character: the low 6 bits of the byte sum, plus 0x30.
  static char sum(const std::string& s) {
    unsigned total = 0;
    for (unsigned char c : s) total += c;
    return static_cast<char>((total & 0x3F) + 0x30);
  }
  static std::string encode(int value, int chars) {
    std::string out(static_cast<std::size_t>(chars), '0');
    for (int i = chars - 1; i >= 0; --i, value >>= 6)
      out[static_cast<std::size_t>(i)] = static_cast<char>((value & 0x3F) + 0x30);
    return out;
  }

 private:
  void send(int fd, const std::string& s) {
    std::size_t off = 0;
    while (off < s.size()) {
      const ssize_t n = ::send(fd, s.data() + off, s.size() - off, MSG_NOSIGNAL);
      if (n <= 0) return;
      off += static_cast<std::size_t>(n);
    }
  }
  // Echo, status line, data lines (each with its check character), blank line.
  std::string reply(const std::string& echo, const std::string& status,
                    const std::vector<std::string>& lines) {
    std::string r = echo + "\n" + status + sum(status) + "\n";
    for (const auto& l : lines) r += l + sum(l) + "\n";
    return r + "\n";
  }
  std::string scanReply(const std::string& echo, std::size_t k, int first, int last) {
    std::string data;
    const auto& s = scans_[k % scans_.size()];
    for (int i = first; i <= last; ++i)
      data += encode(i < static_cast<int>(s.size()) ? s[static_cast<std::size_t>(i)] : 0, 3);
    std::vector<std::string> lines = {encode(static_cast<int>(k * period_ * 1000) & 0xFFFFFF, 4)};
    for (std::size_t p = 0; p < data.size(); p += 64) lines.push_back(data.substr(p, 64));
    return reply(echo, "99", lines);
  }

  void run() {
    int fd = -1;
    std::string in;
    bool streaming = false;
    std::string md;
    int first = 0, last = 0;
    std::size_t k = 0;
    auto next = std::chrono::steady_clock::now();
    while (!quit_) {
      if (fd < 0) {
        pollfd p{listen_, POLLIN, 0};
        if (::poll(&p, 1, 20) > 0) fd = ::accept(listen_, nullptr, nullptr);
        continue;
      }
      pollfd p{fd, POLLIN, 0};
      if (::poll(&p, 1, 5) > 0) {
        char buf[256];
        const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
        if (n <= 0) {
          ::close(fd);
          fd = -1;
          streaming = false;
          continue;
        }
        in.append(buf, static_cast<std::size_t>(n));
      }
      for (auto nl = in.find('\n'); nl != std::string::npos; nl = in.find('\n')) {
        const std::string cmd = in.substr(0, nl);
        in.erase(0, nl + 1);
        if (cmd.rfind("PP", 0) == 0) {
          const int n_steps = static_cast<int>(scans_.front().size());
          send(fd,
               reply(cmd, "00",
                     {"MODL:UTM-30LX-EW(sketchnav test);", "DMIN:20;",
                      "DMAX:" + std::to_string(dmax_) + ";", "ARES:" + std::to_string(ares_) + ";",
                      "AMIN:0;", "AMAX:" + std::to_string(n_steps - 1) + ";",
                      "AFRT:" + std::to_string((n_steps - 1) / 2) + ";", "SCAN:2400;"}));
        } else if (cmd.rfind("VV", 0) == 0) {
          send(fd, reply(cmd, "00", {"VEND:sketchnav;", "PROD:SCIP emulator;", "PROT:SCIP 2.0;"}));
        } else if (cmd.rfind("MD", 0) == 0 || cmd.rfind("ME", 0) == 0) {
          md = cmd;
          first = std::stoi(cmd.substr(2, 4));
          last = std::stoi(cmd.substr(6, 4));
          send(fd, reply(cmd, "00", {}));
          streaming = true;
          next = std::chrono::steady_clock::now();
        } else if (cmd.rfind("QT", 0) == 0) {
          streaming = false;
          send(fd, reply(cmd, "00", {}));
        } else {  // SCIP2.0, BM, HS, CR, ...: acknowledged
          send(fd, reply(cmd, "00", {}));
        }
      }
      if (streaming && std::chrono::steady_clock::now() >= next) {
        send(fd, scanReply(md, k++, first, last));
        ++sent_;
        next += std::chrono::duration_cast<std::chrono::steady_clock::duration>(
            std::chrono::duration<double>(period_));
      }
    }
    if (fd >= 0) ::close(fd);
  }

  std::vector<std::vector<int>> scans_;
  int ares_, dmax_;
  double period_;
  int listen_ = -1, port_ = 0;
  std::atomic<bool> quit_{false};
  std::atomic<int> sent_{0};
  std::thread thread_;
};

}  // namespace sketchnav::test
