# Warnings are set per target, never through global flags.
function(stokesrods_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor
                                           -Wconversion -Wno-sign-conversion -Wold-style-cast)
endfunction()
