// Retries for clients of a server or of a load balancer in front of several
// (docs/deploy.md, "Clients"): the C++ counterpart of client/python's
// ResilientClient, and the pieces `beamcast load` (an Asio event loop, not
// this blocking client) shares with it: the retry budget and the backoff.
//
// Stated choice (issue 18): servers do not share their scene stores; a client
// that lands on a server without its scene puts it again.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <random>
#include <stdexcept>
#include <string>

#include "client/client.hpp"

namespace beamcast::client {

// Retries allowed as a share of requests, a token bucket: every request earns
// `ratio` of a retry, a retry spends one, at most `burst` are saved up. With
// ratio 0.1 a failing cluster sees at most ~1.1 requests for each request the
// callers make (plus the burst), never a storm. Thread-safe; one per process
// (or per job), shared by all its connections.
class RetryBudget {
 public:
  explicit RetryBudget(double ratio = 0.1, double burst = 10.0);
  void on_request();
  // Takes one retry if the bucket holds one.
  bool try_spend();
  // Retries refused because the bucket was empty.
  std::uint64_t refused() const;

 private:
  mutable std::mutex mu_;
  double ratio_, burst_, tokens_;
  std::uint64_t refused_ = 0;
};

struct RetryPolicy {
  int max_attempts = 5;                 // tries of one request, the first included
  std::chrono::milliseconds base{20};   // backoff before retry k: up to base * 2^k ...
  std::chrono::milliseconds cap{1000};  // ... but never more than cap
};

// "Full jitter": uniform in [0, min(cap, base * 2^attempt)], so clients cut
// off together do not come back together.
std::chrono::microseconds backoff_delay(const RetryPolicy& policy, int attempt,
                                        std::mt19937_64& rng);

// A request the server answered with an error that retrying cannot mend
// (wrong token, bad scene): thrown, not retried.
class RequestRefused : public std::runtime_error {
 public:
  RequestRefused(const std::string& what, ErrorInfo error)
      : std::runtime_error(what), error_(std::move(error)) {}
  const ErrorInfo& error() const { return error_; }

 private:
  ErrorInfo error_;
};

struct ResilientOptions {
  RetryPolicy policy;
  std::chrono::milliseconds connect_timeout{5000};
  std::chrono::milliseconds receive_timeout{60000};
  std::string token;       // presented in hello on every new connection when set
  // Asked for in hello on every new connection when set: "raw" or "raw_zstd"
  // (PROTOCOL.md, "Frame formats").
  std::string frame_format;
  std::uint64_t seed = 1;  // of the jitter
};

struct RetryStats {
  std::uint64_t requests = 0;     // made by the caller
  std::uint64_t retries = 0;      // sent again after a dropped or refused connection
  std::uint64_t reputs = 0;       // scenes put again after unknown_scene
  std::uint64_t connections = 0;  // opened (the first included)
};

// One connection at a time to one endpoint (a server or a balancer), opened on
// first use and again after a transport failure. Idempotent requests (ping,
// scene.put of the same content, render) are sent again on a new connection
// when the connection drops or cannot be made (not when a wait times out:
// TransportTimeout is thrown at once), after backoff_delay,
// while the attempts last and the shared budget allows; then the last
// transport error is thrown (std::runtime_error naming the endpoint and the
// attempts). A render by scene_id answered unknown_scene puts the scene this
// client stored (scene_put) and renders once more. Not thread-safe: one per
// thread, sharing a budget.
class ResilientClient {
 public:
  ResilientClient(Endpoint endpoint, std::shared_ptr<RetryBudget> budget,
                  ResilientOptions options = {});

  Response ping();
  // Stores `scene` for re-puts; a refusal throws RequestRefused.
  Response scene_put(const std::string& scene_id, const nlohmann::json& scene);
  // Frames, or a server error as the result's value (ok false) as Client does.
  RenderResult render(const RenderRequest& request);

  const RetryStats& stats() const { return stats_; }
  std::string endpoint() const;
  void close() { client_.reset(); }

 private:
  Client& connection();
  template <class F>
  auto attempt(F&& fn) -> decltype(fn(std::declval<Client&>()));

  Endpoint endpoint_;
  std::shared_ptr<RetryBudget> budget_;
  ResilientOptions options_;
  std::mt19937_64 rng_;
  std::unique_ptr<Client> client_;
  std::map<std::string, nlohmann::json> scenes_;  // scene_id -> content, for re-puts
  RetryStats stats_;
};

}  // namespace beamcast::client
