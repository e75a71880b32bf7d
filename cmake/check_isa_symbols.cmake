# ctest isa_kernel_symbols: the objects compiled for AVX2 and AVX-512 (src/glint/accel/
# aggregate_avx2.cpp, aggregate_avx512.cpp) must define no global code symbol but their four
# queries: intersect, intersectPacket, transmittance and transmittancePacket (global data, such as inline constexpr
# tables, is allowed).
# A weak copy of an inline function there (one that [[gnu::flatten]] did not inline) could be the
# copy the linker keeps for the whole program, and crash it on a processor without that ISA.
# Usage: cmake -DNM=nm -DOBJECTS="a.o;b.o;..." -P check_isa_symbols.cmake
set(checked 0)
foreach(object IN LISTS OBJECTS)
  if(NOT object MATCHES "aggregate_(avx2|avx512)\\.cpp\\.o$")
    continue()
  endif()
  set(suffix Avx2)
  if(CMAKE_MATCH_1 STREQUAL "avx512")
    set(suffix Avx512)
  endif()
  execute_process(COMMAND ${NM} --defined-only --extern-only ${object}
                  OUTPUT_VARIABLE symbols RESULT_VARIABLE status)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "${NM} failed on ${object}")
  endif()
  string(REPLACE "\n" ";" lines "${symbols}")
  set(kernels 0)
  foreach(line IN LISTS lines)
    if(line STREQUAL "")
      continue()
    endif()
    if(line MATCHES " T _ZNK5glint9Aggregate[0-9]+(intersect|intersectPacket|transmittance|transmittancePacket)${suffix}E")
      math(EXPR kernels "${kernels} + 1")
    elseif(line MATCHES "^[0-9a-f]+ [uVvRrDdBb] ")
      # Data, not code (an inline constexpr table such as slab_test.h's kSlabRows): the same bytes
      # whichever object the linker keeps, and no instruction of the ISA in it.
    else()
      message(SEND_ERROR "${object}: a global symbol other than the four ${suffix} queries: ${line}")
    endif()
  endforeach()
  if(NOT kernels EQUAL 4)
    message(SEND_ERROR "${object}: ${kernels} of the four ${suffix} queries defined")
  endif()
  math(EXPR checked "${checked} + 1")
endforeach()
if(NOT checked EQUAL 2)
  message(FATAL_ERROR "found ${checked} of the two ISA objects in: ${OBJECTS}")
endif()
message(STATUS "the AVX2 and AVX-512 objects define only their queries")
