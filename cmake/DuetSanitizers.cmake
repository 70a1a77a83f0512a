# AddressSanitizer + UndefinedBehaviorSanitizer for the Debug/CI sanitizer build.
function(duet_set_sanitizers target)
  if(DUET_SANITIZE)
    # -O1 keeps the sanitizer build's tests (real motion files, a live server) fast enough.
    # -g1 (line tables only, after the build type's -g) still gives a report's file and line,
    # and builds in 30% less time than full debug information (the CI budget, scripts/test.sh).
    # UBSan's pointer checks (null, alignment, vptr, object-size, pointer-overflow) doubled the
    # compile time of a file using Eigen (56 -> 29 s, session 54): a bad pointer's access is
    # AddressSanitizer's to report; every arithmetic, shift, bounds, cast and enum check stays.
    target_compile_options(${target} PUBLIC -fsanitize=address,undefined -fno-omit-frame-pointer
                                            -fno-sanitize=null,alignment,vptr,object-size
                                            -fno-sanitize=pointer-overflow
                                            -fno-sanitize-recover=all -O1 -g1)
    # Timing bounds (the server's latency percentiles) hold for optimised builds only.
    target_compile_definitions(${target} PUBLIC DUET_SANITIZED=1)
    target_link_options(${target} PUBLIC -fsanitize=address,undefined)
  endif()
endfunction()
