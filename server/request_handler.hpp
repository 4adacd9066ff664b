// What each method does (PROTOCOL.md, "Methods"). Runs on the session's strand;
// render work is handed to the RenderService and answered when it completes.
#pragma once

#include <chrono>
#include <memory>
#include <string_view>

#include "server/server_core.hpp"

namespace beamcast {

class Connection;

void handle_message(ServerCore& core, const std::shared_ptr<Connection>& session,
                    std::string_view json_text, std::chrono::steady_clock::time_point arrived);

// Reserves a message's estimated memory against max_request_memory_bytes
// (server/memory.hpp); if it does not fit, answers the connection (`busy` or
// `limit_exceeded`, id null: the message has not been parsed) and returns false.
bool reserve_request_memory(ServerCore& core, Connection& connection, std::uint64_t message_bytes,
                            MemoryBudget::Reservation* reservation);

}  // namespace beamcast
