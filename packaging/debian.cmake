# The Debian packages (CPack's DEB generator, one package per install component), made by
# scripts/package.sh from a build configured for /usr:
#   libhorus0      (lib)     libhorus.so.0: the library, LCM and the standard messages; horus0/: the DDS transports' plug-ins
#   libhorus-dev   (dev)     headers, the CMake package, horus.pc, horus-idlgen, the IDL and LCM files
#   horus-tools    (tools)   the horus command line, its bash completion, horus-msg-catalogue
#   python3-horus  (python)  the module horus for Debian's python3
# Each package's dependencies on Debian's libraries are read from what its files link
# (dpkg-shlibdeps), so `apt install ./*.deb` on a robot pulls what is missing.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME horus)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_VENDOR "the horus developers")
set(CPACK_PACKAGE_CONTACT "horus developers <horus-dev@lists.horus-robotics.org>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "typed zero-copy topics for robot fleets")
set(CPACK_OUTPUT_FILE_PREFIX ${PROJECT_BINARY_DIR}/packages)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_ALL lib dev tools python)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_RELEASE 1)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# libhorus.so.0 of the other packages is found in the build tree (their dependency on libhorus0
# comes from the components' own dependencies below).
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS_PRIVATE_DIRS ${PROJECT_BINARY_DIR})
# Debian's packages are stripped (debug symbols would go in -dbgsym packages).
set(CPACK_STRIP_FILES ON)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
# The library's own packages depend on one another at this exact version.
set(CPACK_DEBIAN_ENABLE_COMPONENT_DEPENDS ON)
set(_horus_deb_version "${PROJECT_VERSION}-${CPACK_DEBIAN_PACKAGE_RELEASE}")

set(CPACK_COMPONENT_LIB_DESCRIPTION "typed zero-copy topics for robot fleets - shared library
 horus moves typed messages through the fastest path that reaches every
 subscriber: an in-process ring, a shared-memory ring between processes, or
 Cyclone DDS, Fast DDS or LCM between hosts. This package holds libhorus.so.0:
 the library, its network transports and the 81 standard robotics messages.")
set(CPACK_DEBIAN_LIB_PACKAGE_NAME libhorus0)
set(CPACK_DEBIAN_LIB_PACKAGE_SECTION libs)
# shlibs (what a program that links libhorus.so.0 depends on) and the ldconfig trigger.
set(CPACK_DEBIAN_PACKAGE_GENERATE_SHLIBS ON)
set(CPACK_DEBIAN_PACKAGE_GENERATE_SHLIBS_POLICY ">=")
set(CPACK_DEBIAN_LIB_PACKAGE_CONTROL_EXTRA ${CMAKE_CURRENT_LIST_DIR}/triggers)

set(CPACK_COMPONENT_DEV_DESCRIPTION "typed zero-copy topics for robot fleets - development files
 The headers of horus, its CMake package (find_package(horus): horus::horus),
 its pkg-config file (horus.pc), horus-idlgen (OMG IDL and LCM types from C++
 messages) and the standard messages' IDL and LCM files.")
set(CPACK_COMPONENT_DEV_DEPENDS lib)
set(CPACK_DEBIAN_DEV_PACKAGE_NAME libhorus-dev)
set(CPACK_DEBIAN_DEV_PACKAGE_SECTION libdevel)
set(CPACK_DEBIAN_DEV_PACKAGE_DEPENDS
    "libfmt-dev, libspdlog-dev, nlohmann-json3-dev, libeigen3-dev, libdlpack-dev, libmsgpack-cxx-dev")

set(CPACK_COMPONENT_TOOLS_DESCRIPTION "typed zero-copy topics for robot fleets - command line
 The horus command: list, echo, publish and measure topics, watch the fleet,
 record and play MCAP and LCM logs, serve Foxglove, manage DDS-Security keys,
 benchmark round trips.")
set(CPACK_COMPONENT_TOOLS_DEPENDS lib)
set(CPACK_DEBIAN_TOOLS_PACKAGE_NAME horus-tools)
set(CPACK_DEBIAN_TOOLS_PACKAGE_SECTION utils)

set(CPACK_COMPONENT_PYTHON_DESCRIPTION "typed zero-copy topics for robot fleets - Python 3 module
 The module horus for Debian's python3: topics of the standard messages, NumPy
 views of large data, the fleet, recording and playing.")
set(CPACK_COMPONENT_PYTHON_DEPENDS lib)
set(CPACK_DEBIAN_PYTHON_PACKAGE_NAME python3-horus)
set(CPACK_DEBIAN_PYTHON_PACKAGE_SECTION python)
set(CPACK_DEBIAN_PYTHON_PACKAGE_DEPENDS "python3 (>= 3.11), python3 (<< 3.12), python3-numpy")

# Each package's copyright and changelog (/usr/share/doc/<package>/), and the CLI's bash completion.
set(_horus_changelog ${PROJECT_BINARY_DIR}/packaging/changelog.Debian.gz)
file(MAKE_DIRECTORY ${PROJECT_BINARY_DIR}/packaging)
execute_process(COMMAND gzip -9nc ${CMAKE_CURRENT_LIST_DIR}/changelog OUTPUT_FILE ${_horus_changelog})
foreach(pair lib:libhorus0 dev:libhorus-dev tools:horus-tools python:python3-horus)
  string(REPLACE ":" ";" pair ${pair})
  list(GET pair 0 component)
  list(GET pair 1 package)
  install(FILES ${CMAKE_CURRENT_LIST_DIR}/copyright ${_horus_changelog}
          DESTINATION ${CMAKE_INSTALL_DATAROOTDIR}/doc/${package} COMPONENT ${component})
endforeach()
install(FILES ${CMAKE_CURRENT_LIST_DIR}/horus.bash-completion DESTINATION ${CMAKE_INSTALL_DATAROOTDIR}/bash-completion/completions
        RENAME horus COMPONENT tools)

include(CPack)
