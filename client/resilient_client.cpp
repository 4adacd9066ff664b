#include "client/resilient_client.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <thread>
#include <utility>

namespace beamcast::client {

RetryBudget::RetryBudget(double ratio, double burst)
    : ratio_(ratio), burst_(burst), tokens_(burst) {}

void RetryBudget::on_request() {
  std::lock_guard lock(mu_);
  tokens_ = std::min(burst_, tokens_ + ratio_);
}

bool RetryBudget::try_spend() {
  std::lock_guard lock(mu_);
  // Ten requests' 0.1 sum to 0.999...: a hair of slack so they earn one retry.
  if (tokens_ >= 1.0 - 1e-9) {
    tokens_ -= 1.0;
    return true;
  }
  ++refused_;
  return false;
}

std::uint64_t RetryBudget::refused() const {
  std::lock_guard lock(mu_);
  return refused_;
}

std::chrono::microseconds backoff_delay(const RetryPolicy& policy, int attempt,
                                        std::mt19937_64& rng) {
  const double base_us = std::chrono::duration<double, std::micro>(policy.base).count();
  const double cap_us = std::chrono::duration<double, std::micro>(policy.cap).count();
  const double top = std::min(cap_us, base_us * std::ldexp(1.0, std::min(attempt, 30)));
  std::uniform_real_distribution<double> u(0.0, top);
  return std::chrono::microseconds(static_cast<long long>(u(rng)));
}

ResilientClient::ResilientClient(Endpoint endpoint, std::shared_ptr<RetryBudget> budget,
                                 ResilientOptions options)
    : endpoint_(std::move(endpoint)),
      budget_(budget ? std::move(budget) : std::make_shared<RetryBudget>()),
      options_(std::move(options)),
      rng_(options_.seed) {}

std::string ResilientClient::endpoint() const {
  const bool v6 = endpoint_.host.find(':') != std::string::npos;
  return (v6 ? "[" + endpoint_.host + "]" : endpoint_.host) + ":" + std::to_string(endpoint_.port);
}

Client& ResilientClient::connection() {
  if (client_ && client_->is_open()) return *client_;
  client_ = std::make_unique<Client>();
  client_->set_receive_timeout(options_.receive_timeout);
  ++stats_.connections;
  client_->connect(endpoint_.host, endpoint_.port, options_.connect_timeout);
  if (!options_.token.empty() || !options_.frame_format.empty()) {
    nlohmann::json params = {{"protocol", 1}};
    if (!options_.token.empty()) params["token"] = options_.token;
    if (!options_.frame_format.empty()) params["frame_format"] = options_.frame_format;
    const Response h = client_->call("hello", params);
    if (!h.ok) {
      client_.reset();
      throw RequestRefused(endpoint() + " refused hello: [" + h.error.code + "] " + h.error.message,
                           h.error);
    }
  }
  return *client_;
}

template <class F>
auto ResilientClient::attempt(F&& fn) -> decltype(fn(std::declval<Client&>())) {
  ++stats_.requests;
  budget_->on_request();
  const auto start = std::chrono::steady_clock::now();
  for (int tries = 1;; ++tries) {
    try {
      return fn(connection());
    } catch (const RequestRefused&) {
      throw;
    } catch (const TransportTimeout& e) {
      // No answer within the deadline: a retry would wait as long again (and
      // a slow render would run twice). A server that hangs is taken out by
      // the balancer's health checks, which cuts this connection: that drop
      // is retried.
      client_.reset();
      throw TransportTimeout(std::string(e.what()) + " (not retried)");
    } catch (const std::runtime_error& e) {
      // The connection dropped, could not be made, timed out or spoke
      // nonsense: this one is done with; another may land elsewhere.
      client_.reset();
      const bool out_of_tries = tries >= options_.policy.max_attempts;
      if (out_of_tries || !budget_->try_spend()) {
        const double s =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        char when[64];
        std::snprintf(when, sizeof when, "%.2f s", s);
        throw std::runtime_error(std::string(e.what()) + " (gave up after " +
                                 std::to_string(tries) + (tries == 1 ? " try" : " tries") + " in " +
                                 when + (out_of_tries ? "" : "; the retry budget is spent") + ")");
      }
      ++stats_.retries;
      std::this_thread::sleep_for(backoff_delay(options_.policy, tries, rng_));
    }
  }
}

Response ResilientClient::ping() {
  return attempt([](Client& c) { return c.ping(); });
}

Response ResilientClient::scene_put(const std::string& scene_id, const nlohmann::json& scene) {
  scenes_[scene_id] = scene;
  return attempt([&](Client& c) {
    Response r = c.scene_put(scene_id, scene);
    if (!r.ok) {
      throw RequestRefused(endpoint() + " refused scene.put of '" + scene_id + "': [" +
                               r.error.code + "] " + r.error.path +
                               (r.error.path.empty() ? "" : ": ") + r.error.message,
                           r.error);
    }
    return r;
  });
}

RenderResult ResilientClient::render(const RenderRequest& request) {
  return attempt([&](Client& c) {
    RenderResult r = c.render(request);
    if (r.ok || r.error.code != "unknown_scene" || request.scene_id.empty()) return r;
    const auto stored = scenes_.find(request.scene_id);
    if (stored == scenes_.end()) return r;
    // This connection reached a server that never had the scene (or lost
    // it): put it there, then render once more.
    ++stats_.reputs;
    const Response put = c.scene_put(request.scene_id, stored->second);
    if (!put.ok) {
      throw RequestRefused(endpoint() + " refused the re-put of '" + request.scene_id + "': [" +
                               put.error.code + "] " + put.error.message,
                           put.error);
    }
    return c.render(request);
  });
}

}  // namespace beamcast::client
