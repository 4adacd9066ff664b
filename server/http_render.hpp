// POST /v1/render: the protocol's `render` over plain HTTP, for scripts in any
// language (PROTOCOL.md, "HTTP render"), and GET /v1/openapi.json, its
// OpenAPI 3 description (protocol/openapi.json, embedded at build time).
// Each request goes through the same parser, limits, token, memory budget,
// admission and scheduler as a TCP render: it is handed to the request
// handler as a render on a connection of its own.
#pragma once

#include <span>
#include <string_view>

namespace beamcast {

class HttpServer;
struct ServerCore;

// The HTTP status of each error code the endpoint can answer (one table: the
// server and the OpenAPI test read it). Codes not in the table are 500.
int http_status_for_error(std::string_view code);

// Every (code, status) row of that table.
struct HttpErrorStatus {
  std::string_view code;
  int status;
};
std::span<const HttpErrorStatus> http_error_statuses();

// The embedded protocol/openapi.json.
std::string_view openapi_document();

void register_http_render_routes(HttpServer& http, ServerCore& core);

}  // namespace beamcast
