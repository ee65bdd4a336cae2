# The emitted .lcm files go through lcm-gen for C, C++, Java and Python with no diagnostic (no
# output at all, exit 0), and the generated C++ compiles warning-free:
#   cmake -DLCM_DIR=<build>/lcm -DWIRE_LCM_DIR=<test lcm> -DCXX=<c++ compiler> -DWORK_DIR=<dir>
#         -P check_lcm_gen.cmake
# Exits 77 (a skip) when lcm-gen is not installed.
find_program(_lcm_gen lcm-gen)
if(NOT _lcm_gen)
  message("SKIP: lcm-gen is not installed (Debian: liblcm-bin)")
  cmake_language(EXIT 77)
endif()
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR}/c ${WORK_DIR}/cpp ${WORK_DIR}/java ${WORK_DIR}/python)
file(GLOB _lcm ${LCM_DIR}/*.lcm)
list(LENGTH _lcm _n)
if(_n EQUAL 0)
  message(FATAL_ERROR "no .lcm file in ${LCM_DIR}")
endif()
list(APPEND _lcm ${WIRE_LCM_DIR}/wiretest.lcm)
foreach(args "-c;--c-cpath;${WORK_DIR}/c;--c-hpath;${WORK_DIR}/c" "-x;--cpp-hpath;${WORK_DIR}/cpp"
             "-j;--jpath;${WORK_DIR}/java" "-p;--ppath;${WORK_DIR}/python")
  execute_process(COMMAND ${_lcm_gen} ${args} ${_lcm} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err
                  TIMEOUT 300)
  if(NOT rc EQUAL 0 OR NOT "${out}${err}" STREQUAL "")
    message(FATAL_ERROR "lcm-gen ${args}: exit ${rc}\n${out}${err}")
  endif()
endforeach()
# The generated C++ (one translation unit including every header) compiles with -Werror.
file(GLOB_RECURSE _hpp RELATIVE ${WORK_DIR}/cpp ${WORK_DIR}/cpp/*.hpp)
set(_tu "")
foreach(h IN LISTS _hpp)
  string(APPEND _tu "#include \"${h}\"\n")
endforeach()
string(APPEND _tu "int main() { return 0; }\n")
file(WRITE ${WORK_DIR}/all_types.cpp "${_tu}")
execute_process(COMMAND ${CXX} -std=c++17 -Wall -Wextra -Werror -fsyntax-only -I ${WORK_DIR}/cpp ${WORK_DIR}/all_types.cpp
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 300)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the C++ lcm-gen wrote does not compile warning-free:\n${out}${err}")
endif()
list(LENGTH _lcm n)
list(LENGTH _hpp m)
message("lcm-gen: ${n} files accepted by -c, -x, -j and -p without a diagnostic; ${m} C++ headers compile with -Werror")
