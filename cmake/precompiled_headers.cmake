# Precompiled headers (GCC, STOKESRODS_PCH): Eigen's headers (and GoogleTest's for the tests) are
# parsed once per build instead of once per file, which took a third of each file's compile time
# (docs/reliability.md, "The build on the AMD host"). Two headers only, each shared by
# REUSE_FROM: one for the module libraries (position-independent code), one for the test programs
# (position-independent executables); GCC uses a precompiled header only where the flags and
# macros it depends on are those it was made with, and otherwise reads the headers as text (no
# other effect). Files with flags of their own (an instruction set, -fno-math-errno) skip it.
# Clang (the fuzzer's build) and STOKESRODS_PCH=OFF read every header as text, which also checks
# each file's own includes.
set(stokesrods_pch_common <vector> <string> <memory> <algorithm> <cmath> <Eigen/Core>
                          <Eigen/Geometry> <Eigen/LU>)

# stokesrods_precompile(TARGET KIND): KIND is LIBRARY or TEST; the first target of each kind
# makes the header, the others reuse it.
function(stokesrods_precompile target kind)
  if(NOT STOKESRODS_PCH OR NOT CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    return()
  endif()
  get_property(owner GLOBAL PROPERTY stokesrods_pch_owner_${kind})
  if(owner)
    target_precompile_headers(${target} REUSE_FROM ${owner})
  elseif(kind STREQUAL "TEST")
    target_precompile_headers(${target} PRIVATE ${stokesrods_pch_common} <gtest/gtest.h>)
    set_property(GLOBAL PROPERTY stokesrods_pch_owner_${kind} ${target})
  else()
    target_precompile_headers(${target} PRIVATE ${stokesrods_pch_common})
    set_property(GLOBAL PROPERTY stokesrods_pch_owner_${kind} ${target})
  endif()
endfunction()
