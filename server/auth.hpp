// Access control (docs/security.md): who may bind where, and the shared-token
// check of `hello`. A server on a loopback address is open to local processes;
// any other bind address needs a token unless explicitly run insecure.
#pragma once

#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "server/config.hpp"

namespace beamcast {

// True for 127.0.0.0/8 and ::1 (and v4-mapped loopback). Throws
// std::invalid_argument if `address` is not an IP address.
bool is_loopback_address(const std::string& address);

// Refuses (std::invalid_argument, naming the fix) a non-loopback bind without
// a token unless config.insecure_no_token is set.
void check_bind_policy(const ServerConfig& config);

// Whether clients must authenticate with `hello` before anything else.
inline bool token_required(const ServerConfig& config) { return !config.token.empty(); }

// Compares a presented token with the configured one in time that depends
// only on the length of the configured token, not on where they differ.
bool token_matches(std::string_view presented, std::string_view expected);

// The HTTP listener's gate: with a token configured, routes that return
// data or render (/api/..., /metrics, POST /v1/render) need "Authorization:
// Bearer <token>"; the preview page's static files, /health,
// /v1/openapi.json and the WebSocket upgrade (which then goes through hello
// like TCP) do not. `path` excludes the query string.
bool http_request_authorized(const ServerConfig& config, std::string_view path,
                             std::string_view authorization_header);

// The gate in front of every request (PROTOCOL.md, "Token"); does nothing
// without a configured token. A method that presents the token (`hello`,
// `presents_token`: the dispatch table's attribute) must carry it in
// params.token (a string), also on an already authenticated connection: a
// missing, non-string or wrong token throws ProtocolError "unauthorized" at
// /params/token. Any other method on a connection that is not authenticated
// throws "unauthorized". Passing this check does not authenticate: the caller
// marks the connection only once its hello has succeeded.
void check_request_token(const ServerConfig& config, bool presents_token,
                         const nlohmann::json& params, bool authenticated);

}  // namespace beamcast
