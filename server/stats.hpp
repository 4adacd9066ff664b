// Server counters for the `stats` method. Thread-safe.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>

#include <nlohmann/json.hpp>

namespace beamcast {

class ServerStats {
 public:
  void count_request(const std::string& method);
  void count_error(const std::string& code);
  void count_frames(std::uint64_t frames) { frames_ += frames; }
  void count_bytes_out(std::uint64_t bytes) { bytes_out_ += bytes; }
  void connection_opened() {
    ++connections_open_;
    ++connections_total_;
  }
  void connection_closed() { --connections_open_; }
  // A connection was closed on the network side (its renders are dropped from
  // then on; the object lives until its last render completes).
  void connection_gone() { ++connections_gone_; }
  std::uint64_t connections_gone() const { return connections_gone_.load(); }
  int connections_open() const { return connections_open_.load(); }
  std::uint64_t errors(const std::string& code) const;

  nlohmann::json to_json() const;

 private:
  const std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  mutable std::mutex mu_;
  std::map<std::string, std::uint64_t> requests_;
  std::map<std::string, std::uint64_t> errors_;
  std::atomic<std::uint64_t> frames_{0};
  std::atomic<std::uint64_t> bytes_out_{0};
  std::atomic<int> connections_open_{0};
  std::atomic<std::uint64_t> connections_total_{0};
  std::atomic<std::uint64_t> connections_gone_{0};
};

}  // namespace beamcast
