#!/usr/bin/env bash
# The instruction-set files (*_avx512.cc, *_avx2.cc) must define no inline function shared with
# other files: the linker keeps one copy of each (weak) inline function, whichever object it comes
# from, so a std::vector method compiled there with AVX-512 could be the one every caller runs,
# and fail with an illegal instruction on a CPU without it. Usage: check_isa_objects.sh NM LIB...
# (static libraries); fails listing any weak function those members define (nm's W or w; weak
# data, V or v, such as the typeinfo objects of UBSan's checks, holds no instructions).
set -euo pipefail
nm_tool=$1
shift
found=$("$nm_tool" -A -C --defined-only "$@" |
        grep -E '_avx(512|2)\.cc\.o: ?[0-9a-f]+ [Ww] ' || true)
if [ -n "$found" ]; then
  echo "inline code shared from an instruction-set file:"
  echo "$found"
  exit 1
fi
echo "no weak functions in the instruction-set objects of: $*"
