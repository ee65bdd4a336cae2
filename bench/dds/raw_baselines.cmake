# The raw DDS baselines of the DDS latency benchmark: plain Cyclone DDS (C) and Fast DDS (C++)
# ping-pong programs over what idlc / fastddsgen generate, at build time, from horus's own .idl
# files (geometry.idl, vision.idl from horus_idl; horus_bench.idl from horus_bench_idl). No
# horus code is linked: they measure the DDS stacks alone, with the benchmark's topics and QoS.
#
# Included from bench/CMakeLists.txt. Expects HORUS_IDL_DIR, HORUS_BENCH_IDL_DIR and the
# targets horus_idl / horus_bench_idl; uses HORUS_HAVE_CYCLONEDDS / HORUS_HAVE_FASTDDS.
# Builds raw-cyclone-pingpong and raw-fastdds-pingpong (see the sources for the command line).
# The generated code is not ours and warns: these targets are compiled with -w.

set(_raw_dir ${CMAKE_CURRENT_LIST_DIR})
set(_raw_idl_stems geometry vision horus_bench)
set(_raw_idl_files ${HORUS_IDL_DIR}/geometry.idl ${HORUS_IDL_DIR}/vision.idl ${HORUS_BENCH_IDL_DIR}/horus_bench.idl)
set(_raw_idl_targets horus_idl horus_bench_idl)

# ---- Cyclone DDS: idlc -> <stem>.c / <stem>.h ------------------------------------------------
if(HORUS_HAVE_CYCLONEDDS)
  # find_package(CycloneDDS) ran in backend_dds/; its imported targets are not visible here.
  if(NOT TARGET CycloneDDS::ddsc)
    find_package(CycloneDDS QUIET)
  endif()
  if(TARGET CycloneDDS::idlc)
    set(_raw_idlc CycloneDDS::idlc)
  else()
    find_program(HORUS_IDLC_EXECUTABLE idlc DOC "Cyclone DDS IDL compiler (Debian: cyclonedds-tools)")
    set(_raw_idlc ${HORUS_IDLC_EXECUTABLE})
  endif()
  if(TARGET CycloneDDS::ddsc AND _raw_idlc)
    enable_language(C)
    set(_gen ${CMAKE_CURRENT_BINARY_DIR}/raw_cyclone_gen)
    set(_sources ${_raw_dir}/raw_cyclone_pingpong.c)
    foreach(_idl IN LISTS _raw_idl_files)
      get_filename_component(_stem ${_idl} NAME_WE)
      add_custom_command(OUTPUT ${_gen}/${_stem}.c ${_gen}/${_stem}.h
                         COMMAND ${CMAKE_COMMAND} -E make_directory ${_gen}
                         COMMAND ${_raw_idlc} -I ${HORUS_IDL_DIR} -o ${_gen} ${_idl}
                         DEPENDS ${_idl} ${_raw_idl_targets}
                         COMMENT "idlc: ${_stem}.idl -> raw_cyclone_gen/${_stem}.c"
                         VERBATIM)
      list(APPEND _sources ${_gen}/${_stem}.c)
    endforeach()
    add_executable(raw_cyclone_pingpong ${_sources})
    set_target_properties(raw_cyclone_pingpong PROPERTIES OUTPUT_NAME raw-cyclone-pingpong
                          C_STANDARD 11 C_STANDARD_REQUIRED ON)
    target_include_directories(raw_cyclone_pingpong PRIVATE ${_gen})
    target_compile_options(raw_cyclone_pingpong PRIVATE -w)
    target_link_libraries(raw_cyclone_pingpong PRIVATE CycloneDDS::ddsc Threads::Threads)
    add_dependencies(raw_cyclone_pingpong ${_raw_idl_targets})
    message(STATUS "raw-cyclone-pingpong: raw Cyclone DDS baseline included (idlc: ${_raw_idlc})")
  else()
    message(STATUS "raw-cyclone-pingpong: idlc or CycloneDDS::ddsc not found; the raw Cyclone baseline is left out")
  endif()
endif()

# ---- Fast DDS: fastddsgen -> <stem>.cxx / <stem>PubSubTypes.cxx (+ .h) -----------------------
if(HORUS_HAVE_FASTDDS)
  if(NOT TARGET fastrtps)
    find_package(fastcdr QUIET)
    find_package(fastrtps QUIET)
  endif()
  find_program(HORUS_FASTDDSGEN_EXECUTABLE fastddsgen DOC "Fast DDS IDL generator (Debian: fastddsgen)")
  if(HORUS_FASTDDSGEN_EXECUTABLE)
    set(_gen ${CMAKE_CURRENT_BINARY_DIR}/raw_fastdds_gen)
    set(_outputs "")
    set(_sources ${_raw_dir}/raw_fastdds_pingpong.cpp)
    foreach(_stem IN LISTS _raw_idl_stems)
      list(APPEND _outputs ${_gen}/${_stem}.cxx ${_gen}/${_stem}.h
                           ${_gen}/${_stem}PubSubTypes.cxx ${_gen}/${_stem}PubSubTypes.h)
      list(APPEND _sources ${_gen}/${_stem}.cxx ${_gen}/${_stem}PubSubTypes.cxx)
    endforeach()
    add_custom_command(OUTPUT ${_outputs}
                       COMMAND ${CMAKE_COMMAND} -E make_directory ${_gen}
                       COMMAND ${HORUS_FASTDDSGEN_EXECUTABLE} -replace -d ${_gen} -I ${HORUS_IDL_DIR} ${_raw_idl_files}
                       DEPENDS ${_raw_idl_files} ${_raw_idl_targets}
                       COMMENT "fastddsgen: geometry.idl vision.idl horus_bench.idl -> raw_fastdds_gen/"
                       VERBATIM)
    add_executable(raw_fastdds_pingpong ${_sources})
    # C++20: the generated code and Fast DDS 2.9's headers predate C++23.
    set_target_properties(raw_fastdds_pingpong PROPERTIES OUTPUT_NAME raw-fastdds-pingpong
                          CXX_STANDARD 20 CXX_STANDARD_REQUIRED ON)
    target_include_directories(raw_fastdds_pingpong PRIVATE ${_gen})
    target_compile_options(raw_fastdds_pingpong PRIVATE -w)
    target_link_libraries(raw_fastdds_pingpong PRIVATE fastrtps fastcdr Threads::Threads)
    add_dependencies(raw_fastdds_pingpong ${_raw_idl_targets})
    message(STATUS "raw-fastdds-pingpong: raw Fast DDS baseline included")
  else()
    message(STATUS "raw-fastdds-pingpong: fastddsgen not found; the raw Fast DDS baseline is left out")
  endif()
endif()

unset(_raw_dir)
unset(_raw_idl_stems)
unset(_raw_idl_files)
unset(_raw_idl_targets)
unset(_raw_idlc)
unset(_gen)
unset(_outputs)
unset(_sources)
unset(_stem)
unset(_idl)
