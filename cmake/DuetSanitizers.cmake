# AddressSanitizer + UndefinedBehaviorSanitizer for the Debug/CI sanitizer build.
function(duet_set_sanitizers target)
  if(DUET_SANITIZE)
    target_compile_options(${target} PUBLIC -fsanitize=address,undefined -fno-omit-frame-pointer
                                            -fno-sanitize-recover=all)
    target_link_options(${target} PUBLIC -fsanitize=address,undefined)
  endif()
endfunction()
