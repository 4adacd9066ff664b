#include "server/stats.hpp"

namespace beamcast {

void ServerStats::count_request(const std::string& method) {
  std::lock_guard lock(mu_);
  ++requests_[method];
}

void ServerStats::count_error(const std::string& code) {
  std::lock_guard lock(mu_);
  ++errors_[code];
}

std::uint64_t ServerStats::errors(const std::string& code) const {
  std::lock_guard lock(mu_);
  auto it = errors_.find(code);
  return it == errors_.end() ? 0 : it->second;
}

nlohmann::json ServerStats::to_json() const {
  std::lock_guard lock(mu_);
  return {
      {"uptime_s",
       std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count()},
      {"connections", {{"open", connections_open_.load()}, {"total", connections_total_.load()}}},
      {"requests", requests_},
      {"errors", errors_},
      {"frames", frames_.load()},
      {"bytes_out", bytes_out_.load()},
  };
}

}  // namespace beamcast
