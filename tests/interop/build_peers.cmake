# Builds the third-party peers of the interop tests, at test time, the way a user of another
# DDS or LCM stack would: run idlc, fastddsgen and lcm-gen on horus-idlgen's .idl and .lcm
# files, then compile a plain Cyclone DDS C program, a plain Fast DDS C++ program and a plain
# LCM C program against the generated code.
#
#   cmake -DIDL_DIR=<std idl> -DWIRE_IDL_DIR=<test idl> -DLCM_DIR=<std lcm> -DWIRE_LCM_DIR=<test lcm>
#         -DSRC_DIR=<tests/interop> -DWORK_DIR=<dir> -DCC=<c compiler> -DCXX=<c++ compiler>
#         -P build_peers.cmake
#
# Writes <WORK_DIR>/cyclone_echo, <WORK_DIR>/fastdds_echo and <WORK_DIR>/lcm_echo (and the ROS 2
# peers ros2_peer_cyclone and ros2_peer_fastdds, from ros2/ros2_types.idl); a peer whose
# tools are missing is not built and <WORK_DIR>/<peer>.why says why (its tests then skip with
# that reason).
set(files geometry input navigation perception sensor vision)
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR}/cyc ${WORK_DIR}/fd ${WORK_DIR}/lcm ${WORK_DIR}/obj ${WORK_DIR}/cyc_ros2 ${WORK_DIR}/fd_ros2)
set(idl_files "")
foreach(f IN LISTS files)
  list(APPEND idl_files ${IDL_DIR}/${f}.idl)
endforeach()
list(APPEND idl_files ${WIRE_IDL_DIR}/wiretest.idl)
set(failed FALSE)

# compile(what LANG_COMPILER FLAGS <flags...> SOURCES <files...> OBJECTS_VAR <var>): each source
# compiled to an object of its own, as many at once as the machine has cores (one execute_process
# runs its COMMANDs together), the objects' paths into <var>. The test then waits on the slowest
# unit instead of on the sum of them (fastddsgen's output compiled in one g++ took 90 s of the
# suite's 2-core run).
cmake_host_system_information(RESULT _cores QUERY NUMBER_OF_LOGICAL_CORES)
if(NOT _cores OR _cores LESS 2)
  set(_cores 2)
endif()
function(compile what compiler)
  cmake_parse_arguments(ARG "" "OBJECTS_VAR" "FLAGS;SOURCES" ${ARGN})
  set(objects "")
  set(batch "")
  set(n 0)
  list(LENGTH ARG_SOURCES total)
  set(i 0)
  foreach(src IN LISTS ARG_SOURCES)
    get_filename_component(stem ${src} NAME)
    get_filename_component(dir ${src} DIRECTORY)
    string(MD5 tag "${dir}")
    string(SUBSTRING "${tag}" 0 8 tag)
    set(obj ${WORK_DIR}/obj/${tag}_${stem}.o)
    list(APPEND objects ${obj})
    list(APPEND batch COMMAND ${compiler} ${ARG_FLAGS} -c ${src} -o ${obj})
    math(EXPR n "${n} + 1")
    math(EXPR i "${i} + 1")
    if(n EQUAL _cores OR i EQUAL total)
      execute_process(${batch} RESULTS_VARIABLE rcs OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 600)
      foreach(rc IN LISTS rcs)
        if(NOT rc EQUAL 0)
          message(SEND_ERROR "${what} failed (exit ${rc}):\n${out}${err}")
          set(failed TRUE PARENT_SCOPE)
          break()
        endif()
      endforeach()
      set(batch "")
      set(n 0)
    endif()
  endforeach()
  set(${ARG_OBJECTS_VAR} ${objects} PARENT_SCOPE)
endfunction()

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
  compile("compiling cyclone_echo" ${CC} FLAGS -O1 -w -I ${WORK_DIR}/cyc SOURCES ${c_sources} OBJECTS_VAR objs)
  run("linking cyclone_echo" ${CC} -o ${WORK_DIR}/cyclone_echo ${objs} -lddsc)
  message("cyclone_echo built from idlc output")
  # The ROS 2 peer: ROS 2's types, named as its rmw layers name them (ros2/ros2_types.idl).
  run("idlc ros2_types.idl" ${IDLC} -o ${WORK_DIR}/cyc_ros2 ${SRC_DIR}/ros2/ros2_types.idl)
  compile("compiling ros2_peer_cyclone" ${CC} FLAGS -O1 -w -I ${WORK_DIR}/cyc_ros2 -I ${SRC_DIR}/ros2
          SOURCES ${SRC_DIR}/ros2/ros2_peer_cyclone.c ${WORK_DIR}/cyc_ros2/ros2_types.c OBJECTS_VAR objs)
  run("linking ros2_peer_cyclone" ${CC} -o ${WORK_DIR}/ros2_peer_cyclone ${objs} -lddsc)
  message("ros2_peer_cyclone built from idlc output")
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
  compile("compiling fastdds_echo" ${CXX} FLAGS -std=c++20 -O0 -w -I ${WORK_DIR}/fd SOURCES ${cxx_sources} OBJECTS_VAR objs)
  run("linking fastdds_echo" ${CXX} -o ${WORK_DIR}/fastdds_echo ${objs} -lfastrtps -lfastcdr -lpthread)
  message("fastdds_echo built from fastddsgen output")
  run("fastddsgen ros2_types.idl" ${FASTDDSGEN} -replace -d ${WORK_DIR}/fd_ros2 ${SRC_DIR}/ros2/ros2_types.idl)
  compile("compiling ros2_peer_fastdds" ${CXX} FLAGS -std=c++20 -O0 -w -I ${WORK_DIR}/fd_ros2 -I ${SRC_DIR}/ros2
          SOURCES ${SRC_DIR}/ros2/ros2_peer_fastdds.cpp ${WORK_DIR}/fd_ros2/ros2_types.cxx
                  ${WORK_DIR}/fd_ros2/ros2_typesPubSubTypes.cxx OBJECTS_VAR objs)
  run("linking ros2_peer_fastdds" ${CXX} -o ${WORK_DIR}/ros2_peer_fastdds ${objs} -lfastrtps -lfastcdr -lpthread)
  message("ros2_peer_fastdds built from fastddsgen output")
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
  compile("compiling lcm_echo" ${CC} FLAGS -std=c11 -D_POSIX_C_SOURCE=200809L -O1 -w -I ${WORK_DIR}/lcm
          SOURCES ${lcm_sources} OBJECTS_VAR objs)
  run("linking lcm_echo" ${CC} -o ${WORK_DIR}/lcm_echo ${objs} -llcm)
  list(LENGTH lcm_sources n)
  math(EXPR n "${n} - 1")
  message("lcm_echo built from lcm-gen -c output (${n} types)")
endif()
if(failed)
  message(FATAL_ERROR "building the interop peers failed")
endif()
