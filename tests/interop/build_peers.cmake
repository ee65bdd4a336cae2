# Builds the third-party peers of the interop tests, at test time, the way a user of another
# DDS or LCM stack would: run idlc, fastddsgen and lcm-gen on horus-idlgen's .idl and .lcm
# files, then compile a plain Cyclone DDS C program, a plain Fast DDS C++ program and a plain
# LCM C program against the generated code.
#
#   cmake -DIDL_DIR=<std idl> -DWIRE_IDL_DIR=<test idl> -DLCM_DIR=<std lcm> -DWIRE_LCM_DIR=<test lcm>
#         -DSRC_DIR=<tests/interop> -DWORK_DIR=<dir> -DCC=<c compiler> -DCXX=<c++ compiler>
#         -P build_peers.cmake
#
# Writes <WORK_DIR>/cyclone_echo, <WORK_DIR>/fastdds_echo and <WORK_DIR>/lcm_echo; a peer whose
# tools are missing is not built and <WORK_DIR>/<peer>.why says why (its tests then skip with
# that reason).
set(files geometry input navigation perception sensor vision)
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR}/cyc ${WORK_DIR}/fd ${WORK_DIR}/lcm)
set(idl_files "")
foreach(f IN LISTS files)
  list(APPEND idl_files ${IDL_DIR}/${f}.idl)
endforeach()
list(APPEND idl_files ${WIRE_IDL_DIR}/wiretest.idl)
set(failed FALSE)

function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 600)
  if(NOT rc EQUAL 0)
    message(SEND_ERROR "${what} failed (exit ${rc}):\n${out}${err}")
    set(failed TRUE PARENT_SCOPE)
  endif()
endfunction()

# Cyclone DDS: idlc -> C, one descriptor per type.
find_program(IDLC idlc)
if(NOT IDLC OR NOT EXISTS /usr/include/dds/dds.h)
  file(WRITE ${WORK_DIR}/cyclone_echo.why "idlc or the Cyclone DDS headers are missing (Debian: cyclonedds-tools, cyclonedds-dev)")
else()
  set(c_sources ${SRC_DIR}/cyclone_echo.c)
  foreach(idl IN LISTS idl_files)
    run("idlc ${idl}" ${IDLC} -I ${IDL_DIR} -o ${WORK_DIR}/cyc ${idl})
    get_filename_component(stem ${idl} NAME_WE)
    list(APPEND c_sources ${WORK_DIR}/cyc/${stem}.c)
  endforeach()
  run("compiling cyclone_echo" ${CC} -O1 -w -o ${WORK_DIR}/cyclone_echo ${c_sources} -I ${WORK_DIR}/cyc -lddsc)
  message("cyclone_echo built from idlc output")
endif()

# Fast DDS: fastddsgen -> C++ classes and PubSubTypes.
find_program(FASTDDSGEN fastddsgen)
if(NOT FASTDDSGEN OR NOT EXISTS /usr/include/fastdds/dds/domain/DomainParticipant.hpp)
  file(WRITE ${WORK_DIR}/fastdds_echo.why "fastddsgen or the Fast DDS headers are missing (Debian: fastddsgen, libfastrtps-dev)")
else()
  run("fastddsgen" ${FASTDDSGEN} -replace -d ${WORK_DIR}/fd -I ${IDL_DIR} ${idl_files})
  set(cxx_sources ${SRC_DIR}/fastdds_echo.cpp)
  foreach(idl IN LISTS idl_files)
    get_filename_component(stem ${idl} NAME_WE)
    list(APPEND cxx_sources ${WORK_DIR}/fd/${stem}.cxx ${WORK_DIR}/fd/${stem}PubSubTypes.cxx)
  endforeach()
  run("compiling fastdds_echo" ${CXX} -std=c++20 -O0 -w -o ${WORK_DIR}/fastdds_echo ${cxx_sources} -I ${WORK_DIR}/fd
      -lfastrtps -lfastcdr -lpthread)
  message("fastdds_echo built from fastddsgen output")
endif()
# LCM: lcm-gen -c -> <pkg>_<Type>.c / .h for every type of every .lcm file.
find_program(LCM_GEN lcm-gen)
if(NOT LCM_GEN OR NOT EXISTS /usr/include/lcm/lcm.h)
  file(WRITE ${WORK_DIR}/lcm_echo.why "lcm-gen or the LCM headers are missing (Debian: liblcm-bin, liblcm-dev)")
else()
  file(GLOB lcm_files ${LCM_DIR}/*.lcm)
  list(APPEND lcm_files ${WIRE_LCM_DIR}/wiretest.lcm)
  run("lcm-gen -c" ${LCM_GEN} -c --c-cpath ${WORK_DIR}/lcm --c-hpath ${WORK_DIR}/lcm ${lcm_files})
  set(headers "")
  set(entries "")
  set(lcm_sources ${SRC_DIR}/lcm_echo.c)
  foreach(f IN LISTS lcm_files)
    file(STRINGS ${f} lines REGEX "^(package|struct) ")
    set(pkg "")
    foreach(line IN LISTS lines)
      if(line MATCHES "^package ([A-Za-z0-9_]+);")
        set(pkg ${CMAKE_MATCH_1})
      elseif(line MATCHES "^struct ([A-Za-z0-9_]+)")
        string(APPEND headers "#include \"${pkg}_${CMAKE_MATCH_1}.h\"\n")
        string(APPEND entries "HORUS_LCM_TYPE(${pkg}, ${CMAKE_MATCH_1})\n")
        list(APPEND lcm_sources ${WORK_DIR}/lcm/${pkg}_${CMAKE_MATCH_1}.c)
      endif()
    endforeach()
  endforeach()
  file(WRITE ${WORK_DIR}/lcm/lcm_echo_headers.h "${headers}")
  file(WRITE ${WORK_DIR}/lcm/lcm_echo_types.inc "${entries}")
  run("compiling lcm_echo" ${CC} -std=c11 -D_POSIX_C_SOURCE=200809L -O1 -w -o ${WORK_DIR}/lcm_echo ${lcm_sources}
      -I ${WORK_DIR}/lcm -llcm)
  list(LENGTH lcm_sources n)
  math(EXPR n "${n} - 1")
  message("lcm_echo built from lcm-gen -c output (${n} types)")
endif()
if(failed)
  message(FATAL_ERROR "building the interop peers failed")
endif()
