# Builds the third-party peers of the interop tests, at test time, the way a user of another
# DDS stack would: run idlc and fastddsgen on horus-idlgen's .idl files, then compile a plain
# Cyclone DDS C program and a plain Fast DDS C++ program against the generated code.
#
#   cmake -DIDL_DIR=<std idl> -DWIRE_IDL_DIR=<test idl> -DSRC_DIR=<tests/interop> -DWORK_DIR=<dir>
#         -DCC=<c compiler> -DCXX=<c++ compiler> -P build_peers.cmake
#
# Writes <WORK_DIR>/cyclone_echo and <WORK_DIR>/fastdds_echo; a peer whose tools are missing
# is not built and <WORK_DIR>/<peer>.why says why (its tests then skip with that reason).
set(files geometry input navigation perception sensor vision)
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR}/cyc ${WORK_DIR}/fd)
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
if(failed)
  message(FATAL_ERROR "building the interop peers failed")
endif()
