// What each method does (PROTOCOL.md, "Methods"). Runs on the session's strand;
// render work is handed to the RenderService and answered when it completes.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <string_view>

#include "protocol/request.hpp"
#include "server/server_core.hpp"

namespace beamcast {

class Connection;

// Handles one message; true when done. A render or scene method whose scene
// reads asset files (scene_reads_files) is handed to core.loaders after
// parsing, if the caller gives `resume`: then false, and `resume` is called
// on the loader thread once the message has been handled; the caller reads
// the connection's next message only then, so its messages are handled in
// order while the network thread serves other connections.
bool handle_message(ServerCore& core, const std::shared_ptr<Connection>& session,
                    std::string_view json_text, std::chrono::steady_clock::time_point arrived,
                    std::function<void()> resume = {});

// As handle_message, for a request already parsed (POST /v1/render: the
// HTTP body is the params).
bool handle_request(ServerCore& core, const std::shared_ptr<Connection>& session, Request request,
                    std::chrono::steady_clock::time_point arrived,
                    std::function<void()> resume = {});

// Reserves a message's estimated memory against max_request_memory_bytes
// (server/memory.hpp); if it does not fit, answers the connection (`busy` or
// `limit_exceeded`, id null: the message has not been parsed) and returns false.
bool reserve_request_memory(ServerCore& core, Connection& connection, std::uint64_t message_bytes,
                            MemoryBudget::Reservation* reservation);

}  // namespace beamcast
