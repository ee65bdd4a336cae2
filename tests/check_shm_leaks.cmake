# Fails when a test left a shared-memory segment: test topics are named test.* and the
# segment tests use namespaces test<pid>.
file(GLOB leftovers /dev/shm/horus.*.test.* /dev/shm/horus.test*)
if(leftovers)
  foreach(f IN LISTS leftovers)
    file(REMOVE ${f})
  endforeach()
  message(FATAL_ERROR "segments left in /dev/shm by the tests (now removed): ${leftovers}")
endif()
message(STATUS "no test segment left in /dev/shm")
