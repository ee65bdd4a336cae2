# The raw LCM baseline of the LCM latency benchmark: raw-lcm-pingpong, a plain C program over
# liblcm and the C code `lcm-gen -c` generates, at build time, from horus's own .lcm files
# (geometry.lcm and vision.lcm from horus_lcm_types; horus_bench.lcm from horus_bench_idl).
# No horus code is linked: it measures LCM alone, with the benchmark's channels and types.
#
# Included from bench/CMakeLists.txt when HORUS_HAVE_LCM is ON. Expects HORUS_LCM_TYPES_DIR,
# HORUS_BENCH_LCM_DIR and the targets horus_lcm_types / horus_bench_idl. Needs lcm-gen
# (Debian: liblcm-bin); without it the baseline is left out. The generated code is not ours and
# warns: the target is compiled with -w.

set(_rl_dir ${CMAKE_CURRENT_LIST_DIR})
set(_rl_targets horus_lcm_types horus_bench_idl)
find_program(HORUS_LCM_GEN_EXECUTABLE lcm-gen DOC "LCM type generator (Debian: liblcm-bin)")

# liblcm: what backend_lcm/ found (HORUS_LCM_INCLUDE_DIR / HORUS_LCM_LIBRARY; this file is
# included only when it did).
set(_rl_lib ${HORUS_LCM_LIBRARY})
set(_rl_include ${HORUS_LCM_INCLUDE_DIR})

if(NOT HORUS_LCM_GEN_EXECUTABLE)
  message(STATUS "raw-lcm-pingpong: lcm-gen not found (Debian: liblcm-bin); the raw LCM baseline is left out")
else()
  enable_language(C)
  set(_gen ${CMAKE_CURRENT_BINARY_DIR}/raw_lcm_gen)
  # lcm-gen writes every struct of a file; only the types the program uses are listed (and compiled).
  # <lcm file>|<generated stems>|<headers only>
  set(_rl_jobs
      "${HORUS_LCM_TYPES_DIR}/geometry.lcm|horus_msg_CmdVel|"
      "${HORUS_LCM_TYPES_DIR}/vision.lcm|horus_msg_Image|horus_msg_ImageEncoding"
      "${HORUS_BENCH_LCM_DIR}/horus_bench.lcm|horus_bench_Kilobyte|")
  set(_sources ${_rl_dir}/raw_lcm_pingpong.c)
  foreach(_job IN LISTS _rl_jobs)
    string(REPLACE "|" ";" _job "${_job}")
    list(GET _job 0 _lcm)
    list(GET _job 1 _stem)
    list(GET _job 2 _hdr)
    get_filename_component(_name ${_lcm} NAME)
    set(_outputs ${_gen}/${_stem}.c ${_gen}/${_stem}.h)
    if(_hdr)
      list(APPEND _outputs ${_gen}/${_hdr}.h)
    endif()
    add_custom_command(OUTPUT ${_outputs}
                       COMMAND ${CMAKE_COMMAND} -E make_directory ${_gen}
                       COMMAND ${HORUS_LCM_GEN_EXECUTABLE} -c --c-cpath ${_gen} --c-hpath ${_gen} ${_lcm}
                       DEPENDS ${_lcm} ${_rl_targets}
                       COMMENT "lcm-gen -c: ${_name} -> raw_lcm_gen/${_stem}.c"
                       VERBATIM)
    list(APPEND _sources ${_gen}/${_stem}.c)
  endforeach()
  add_executable(raw_lcm_pingpong ${_sources})
  set_target_properties(raw_lcm_pingpong PROPERTIES OUTPUT_NAME raw-lcm-pingpong
                        C_STANDARD 11 C_STANDARD_REQUIRED ON C_EXTENSIONS OFF)
  target_include_directories(raw_lcm_pingpong PRIVATE ${_gen})
  if(_rl_include)
    target_include_directories(raw_lcm_pingpong PRIVATE ${_rl_include})
  endif()
  target_compile_options(raw_lcm_pingpong PRIVATE -w)
  target_link_libraries(raw_lcm_pingpong PRIVATE ${_rl_lib} Threads::Threads)
  add_dependencies(raw_lcm_pingpong ${_rl_targets})
  message(STATUS "raw-lcm-pingpong: raw LCM baseline included (lcm-gen: ${HORUS_LCM_GEN_EXECUTABLE})")
endif()

unset(_rl_dir)
unset(_rl_targets)
unset(_rl_lib)
unset(_rl_include)
unset(_rl_jobs)
unset(_gen)
unset(_outputs)
unset(_sources)
unset(_job)
unset(_lcm)
unset(_stem)
unset(_hdr)
unset(_name)
