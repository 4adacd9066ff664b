# beamcast_pch(TARGET GROUP...): precompiled headers for TARGET's own files, in
# the builds that clang-14 compiles (the sanitizer and fuzz presets). Each GROUP
# names a list of headers below; CMake builds one header per target and
# force-includes it in each of the target's files.
#
# Not under g++ (the release build): there it did not pay. Whole builds side by
# side (docs/performance.md, "The test command's time"): the clang-14
# sanitizer build took 0.78 of its CPU time without (1 036 against 1 335 s,
# building the headers included), the fuzz build 0.70; under g++ the files
# took 1.01 of their time, plus 131 s to build the headers (g++ loads its
# whole precompiled header, 116-248 MB, into each compile; clang reads its
# 28-58 MB lazily).
#
# The sources keep their own #includes: a build with -DBEAMCAST_PCH=OFF
# compiles the same, and the release build (no precompiled headers) checks
# that every file includes what it uses.
option(BEAMCAST_PCH "Precompiled headers where clang compiles: the standard library, nlohmann-json, GoogleTest, Boost.Asio/Beast, CLI11" ON)

set(BEAMCAST_PCH_STD <algorithm> <array> <atomic> <chrono> <cmath> <cstdint> <cstdio>
  <cstdlib> <cstring> <filesystem> <fstream> <functional> <limits> <map> <memory> <mutex>
  <numbers> <optional> <random> <set> <span> <sstream> <stdexcept> <string>
  <string_view> <thread> <utility> <variant> <vector>)
set(BEAMCAST_PCH_JSON <nlohmann/json.hpp>)
set(BEAMCAST_PCH_GTEST <gtest/gtest.h>)
set(BEAMCAST_PCH_ASIO <boost/asio/io_context.hpp> <boost/asio/ip/tcp.hpp>
  <boost/asio/steady_timer.hpp> <boost/asio/post.hpp> <boost/asio/write.hpp>
  <boost/asio/read.hpp> <boost/asio/connect.hpp>)
set(BEAMCAST_PCH_BEAST <boost/beast/core.hpp> <boost/beast/http.hpp>
  <boost/beast/websocket.hpp>)
set(BEAMCAST_PCH_CLI <CLI/CLI.hpp>)

function(beamcast_pch target)
  if(NOT BEAMCAST_PCH OR NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    return()
  endif()
  set(headers)
  foreach(group IN LISTS ARGN)
    if(NOT DEFINED BEAMCAST_PCH_${group})
      message(FATAL_ERROR "beamcast_pch(${target}): no header group ${group}")
    endif()
    list(APPEND headers ${BEAMCAST_PCH_${group}})
  endforeach()
  target_precompile_headers(${target} PRIVATE ${headers})
endfunction()
