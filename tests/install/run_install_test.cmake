# Installs the build tree into a scratch prefix as a user would, then, from the installed files
# only: configures, builds and runs a small consumer project that uses find_package(horus) and
# horus::horus; builds and runs the same program with `pkg-config --cflags --libs horus` (when
# the build made libhorus.so); runs the installed `horus --version`; imports the installed Python
# package (when the build made it); and uninstalls (every file of install_manifest.txt),
# checking that nothing is left behind.
file(REMOVE_RECURSE ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)
execute_process(COMMAND ${CMAKE_COMMAND} --install ${HORUS_BINARY_DIR} --prefix ${prefix}
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cmake --install failed (${rc})")
endif()

# 1. find_package(horus)
execute_process(COMMAND ${CMAKE_COMMAND} -S ${CONSUMER_SOURCE_DIR} -B ${WORK_DIR}/build -G ${GENERATOR}
                        -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "configuring the consumer project failed (${rc})")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${WORK_DIR}/build RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "building the consumer project failed (${rc})")
endif()
execute_process(COMMAND ${WORK_DIR}/build/consumer RESULT_VARIABLE rc OUTPUT_VARIABLE out)
message(STATUS "consumer printed: ${out}")
if(NOT rc EQUAL 0 OR NOT out MATCHES "received CmdVel linear=1.5")
  message(FATAL_ERROR "the consumer did not run as expected (exit ${rc})")
endif()

# The installed library, and where its pkg-config file is.
file(GLOB_RECURSE libs LIST_DIRECTORIES false "${prefix}/lib*/libhorus.so.*")
list(FILTER libs EXCLUDE REGEX "/python|/site-packages|/dist-packages")
if(libs)
  list(GET libs 0 lib)
  get_filename_component(libdir ${lib} DIRECTORY)
  if(NOT EXISTS ${libdir}/pkgconfig/horus.pc)
    message(FATAL_ERROR "no ${libdir}/pkgconfig/horus.pc beside ${lib}")
  endif()
  # 2. pkg-config: the consumer's main.cpp, built by hand.
  find_program(PKG_CONFIG pkg-config REQUIRED)
  set(ENV{PKG_CONFIG_PATH} ${libdir}/pkgconfig)
  execute_process(COMMAND ${PKG_CONFIG} --cflags --libs horus OUTPUT_VARIABLE flags RESULT_VARIABLE rc
                  OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "pkg-config --cflags --libs horus failed (${rc})")
  endif()
  message(STATUS "pkg-config --cflags --libs horus: ${flags}")
  separate_arguments(flags UNIX_COMMAND "${flags}")
  execute_process(COMMAND c++ -O1 ${CONSUMER_SOURCE_DIR}/main.cpp -o ${WORK_DIR}/consumer_pc ${flags}
                  RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "building the consumer with pkg-config's flags failed (${rc})")
  endif()
  execute_process(COMMAND ${CMAKE_COMMAND} -E env LD_LIBRARY_PATH=${libdir} ${WORK_DIR}/consumer_pc
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out)
  if(NOT rc EQUAL 0 OR NOT out MATCHES "received CmdVel linear=1.5")
    message(FATAL_ERROR "the pkg-config consumer did not run as expected (exit ${rc}): ${out}")
  endif()
  execute_process(COMMAND readelf -d ${lib} OUTPUT_VARIABLE dynamic)
  if(NOT dynamic MATCHES "SONAME[^\n]*libhorus\\.so\\.0")
    message(FATAL_ERROR "${lib} has no SONAME libhorus.so.0:\n${dynamic}")
  endif()
endif()

# 3. The installed CLI (it finds the installed library by its RPATH, bin/../lib).
if(EXISTS ${prefix}/bin/horus)
  execute_process(COMMAND ${prefix}/bin/horus --version RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT out MATCHES "^horus [0-9]")
    message(FATAL_ERROR "the installed horus --version failed (exit ${rc}): ${out}${err}")
  endif()
  message(STATUS "installed CLI: ${out}")
endif()

# 4. The installed Python package, imported from outside the build tree.
file(GLOB_RECURSE modules LIST_DIRECTORIES false "${prefix}/*.so")
list(FILTER modules INCLUDE REGEX "/horus/_horus[^/]*\\.so$")
if(PYTHON AND NOT modules)
  message(FATAL_ERROR "the build has the Python package, but the install has no horus/_horus*.so")
endif()
if(modules)
  list(GET modules 0 module)
  get_filename_component(pkg ${module} DIRECTORY)
  get_filename_component(site ${pkg} DIRECTORY)
  execute_process(COMMAND ${CMAKE_COMMAND} -E env PYTHONPATH=${site} PYTHONDONTWRITEBYTECODE=1 ${PYTHON} -c
                          "import horus; print(horus.__version__, horus.__file__)"
                  WORKING_DIRECTORY ${WORK_DIR} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT out MATCHES "${site}")
    message(FATAL_ERROR "importing the installed Python package failed (exit ${rc}): ${out}${err}")
  endif()
  message(STATUS "installed Python package: ${out}")
endif()

# 5. Uninstall: every installed file removed, nothing else left in the prefix.
set(manifest ${HORUS_BINARY_DIR}/install_manifest.txt)
if(NOT EXISTS ${manifest})
  message(FATAL_ERROR "cmake --install wrote no ${manifest}")
endif()
file(STRINGS ${manifest} installed)
foreach(f ${installed})
  file(REMOVE ${f})
endforeach()
file(GLOB_RECURSE left LIST_DIRECTORIES false "${prefix}/*")
if(left)
  list(JOIN left "\n  " left)
  message(FATAL_ERROR "uninstalling left files that install_manifest.txt does not list:\n  ${left}")
endif()
message(STATUS "uninstalled: ${prefix} holds no file")
