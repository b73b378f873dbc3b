# test_isa_objects.cmake - proves the one-binary guarantee of issue 12 on the
# compiled objects (run by ctest as `cmake -P`, see tests/kernel/CMakeLists.txt).
#
# The kernel is compiled once per ISA into the same library. If an object
# compiled for AVX2 or AVX-512 defined a function with vague linkage (an inline
# function or template instantiation emitted as a weak/COMDAT symbol), the
# linker could keep that copy for every caller, and the baseline path would
# execute AVX instructions on a CPU without them. So:
#   1. the wide objects define no weak symbol at all (everything in them is
#      either always-inlined, internal, or a strong symbol with an
#      ISA-suffixed name);
#   2. the baseline objects (the SSE2 kernel and every other object of the
#      library) contain no ymm or zmm register, and the AVX2 object no zmm;
#   3. the checks can fail: the AVX2 object does use ymm and the AVX-512
#      object zmm (otherwise the grep would prove nothing).
#
# Inputs: -DNM=... -DOBJDUMP=... -DBASELINE="a.o;b.o" -DWIDE_avx2=x.o -DWIDE_avx512=y.o
foreach(var NM OBJDUMP BASELINE WIDE_avx2 WIDE_avx512)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "test_isa_objects: ${var} not given")
  endif()
endforeach()

set(failures 0)

function(disassemble obj out)
  execute_process(COMMAND ${OBJDUMP} -d --no-show-raw-insn ${obj} OUTPUT_VARIABLE text RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "objdump failed on ${obj}")
  endif()
  set(${out} "${text}" PARENT_SCOPE)
endfunction()

# 1. No weak symbols in the wide objects (DW.ref.__gxx_personality_v0 is the
#    exception-personality pointer, data shared by every C++ object).
foreach(isa avx2 avx512)
  execute_process(COMMAND ${NM} --defined-only -C ${WIDE_${isa}} OUTPUT_VARIABLE syms RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "nm failed on ${WIDE_${isa}}")
  endif()
  string(REPLACE "\n" ";" lines "${syms}")
  set(weak 0)
  foreach(line IN LISTS lines)
    if(line MATCHES "^[0-9a-f]* [WwVvu] " AND NOT line MATCHES "DW\\.ref\\.__gxx_personality_v0")
      message(SEVERE_ERROR "${isa} object defines a weak symbol: ${line}")
      math(EXPR weak "${weak} + 1")
    endif()
  endforeach()
  message(STATUS "${isa}: ${weak} weak symbols")
  if(weak GREATER 0)
    set(failures 1)
  endif()
endforeach()

# 2. No wide registers in the baseline objects, no zmm in the AVX2 object.
set(checked 0)
foreach(obj IN LISTS BASELINE)
  disassemble(${obj} text)
  if(text MATCHES "%[yz]mm[0-9]")
    string(REGEX MATCH "[^\n]*%[yz]mm[0-9][^\n]*" where "${text}")
    message(SEVERE_ERROR "baseline object ${obj} uses a wide register: ${where}")
    set(failures 1)
  endif()
  math(EXPR checked "${checked} + 1")
endforeach()
message(STATUS "baseline: ${checked} objects without ymm/zmm")
disassemble(${WIDE_avx2} avx2_text)
if(avx2_text MATCHES "%zmm[0-9]")
  message(SEVERE_ERROR "the AVX2 object uses zmm registers")
  set(failures 1)
endif()

# 3. The wide objects do use their registers: the checks above can fail.
if(NOT avx2_text MATCHES "%ymm[0-9]")
  message(SEVERE_ERROR "the AVX2 object has no ymm register: is it compiled for AVX2?")
  set(failures 1)
endif()
disassemble(${WIDE_avx512} avx512_text)
if(NOT avx512_text MATCHES "%zmm[0-9]")
  message(SEVERE_ERROR "the AVX-512 object has no zmm register: is it compiled for AVX-512?")
  set(failures 1)
endif()

if(failures)
  message(FATAL_ERROR "test_isa_objects: FAILED")
endif()
message(STATUS "test_isa_objects: passed")
