# Precompiled headers. Nearly every translation unit of ours parses Eigen, fmt and a dozen standard
# headers, each test GoogleTest and each subcommand CLI11: 3-6 s of every cold compile (measured in
# session 54), parsed once per target instead. DUET_PRECOMPILED_HEADERS=OFF builds without them
# (a file that forgets an include then fails to compile).
option(DUET_PRECOMPILED_HEADERS "Precompile the headers most translation units include" ON)

set(DUET_COMMON_HEADERS
    <algorithm> <array> <cmath> <cstdint> <filesystem> <limits> <memory> <optional> <span>
    <string> <string_view> <vector> <Eigen/Geometry> <fmt/format.h>)

function(duet_precompiled_header_warnings target)
  # A precompiled header the compiler cannot use (other flags) is a silent slow build otherwise.
  target_compile_options(${target} PRIVATE -Winvalid-pch)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    # With <string> from a precompiled header, GCC 12 at -O3 reports false -Wstringop-overflow
    # and -Warray-bounds errors inside std::string's inlined copies, as in "j" + std::to_string(j)
    # (GCC bug 105329, as -Wrestrict: DuetWarnings). The sanitizer build checks bounds at run time.
    target_compile_options(${target} PRIVATE -Wno-stringop-overflow -Wno-array-bounds)
  endif()
endfunction()

# duet_precompile_headers(target [extra headers...]): the common headers and the given ones.
function(duet_precompile_headers target)
  if(DUET_PRECOMPILED_HEADERS)
    target_precompile_headers(${target} PRIVATE ${DUET_COMMON_HEADERS} ${ARGN})
    duet_precompiled_header_warnings(${target})
  endif()
endfunction()

# duet_reuse_precompiled_headers(target from): target compiles with the same flags as `from` and
# uses its precompiled header instead of building its own (the test programs share one).
function(duet_reuse_precompiled_headers target from)
  if(DUET_PRECOMPILED_HEADERS)
    target_precompile_headers(${target} REUSE_FROM ${from})
    duet_precompiled_header_warnings(${target})
  endif()
endfunction()
