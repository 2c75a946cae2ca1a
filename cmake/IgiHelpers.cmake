# Warnings for the project's own code (never for third-party headers, which come in as SYSTEM).
function(igi_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow=local
                         -Wnon-virtual-dtor -Wcast-align -Wnull-dereference)
  if(IGI_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()

include(GNUInstallDirs)

# Installs the headers (*.h) of the calling folder, recursively, under include/igi/<folder>/ so
# that "recon/scene.h" style includes work against include/igi; once per folder tree.
function(igi_install_headers)
  file(RELATIVE_PATH rel ${PROJECT_SOURCE_DIR} ${CMAKE_CURRENT_SOURCE_DIR})
  get_property(done GLOBAL PROPERTY IGI_HEADER_DIRS)
  foreach(dir IN LISTS done)
    if(rel STREQUAL dir OR rel MATCHES "^${dir}/")
      return()
    endif()
  endforeach()
  set_property(GLOBAL APPEND PROPERTY IGI_HEADER_DIRS ${rel})
  install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/igi/${rel}
          FILES_MATCHING PATTERN "*.h")
endfunction()

# igi_add_library(NAME SOURCES ... PUBLIC_DEPS ... PRIVATE_DEPS ...): also installed, with its
# headers, into the igiTargets export set (find_package(igi) gives igi::NAME).
function(igi_add_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(${name} ${ARG_SOURCES})
  target_include_directories(${name} PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>
                                            $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}/igi>)
  target_link_libraries(${name} PUBLIC ${ARG_PUBLIC_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  target_compile_features(${name} PUBLIC cxx_std_20)
  igi_set_warnings(${name})
  install(TARGETS ${name} EXPORT igiTargets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
          RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  igi_install_headers()
endfunction()

# igi_add_executable(NAME SOURCE DEPS ...): one thin main per executable, into build/bin/.
function(igi_add_executable name source)
  add_executable(${name} ${source})
  target_link_libraries(${name} PRIVATE ${ARGN})
  igi_set_warnings(${name})
  install(TARGETS ${name} EXPORT igiTargets RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endfunction()

# igi_add_test(NAME SOURCES ... DEPS ... [LABELS ...] [TIMEOUT s] [TEST_FILTER gtest-filter]): a
# GoogleTest binary registered with ctest (only the tests the filter passes, when given).
function(igi_add_test name)
  cmake_parse_arguments(ARG "" "TIMEOUT;TEST_FILTER" "SOURCES;DEPS;LABELS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gtest_main)
  target_compile_definitions(${name} PRIVATE
      IGI_SHARED_DATA_DIR="${IGI_SHARED_DATA_DIR}"
      IGI_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
      IGI_BIN_DIR="${CMAKE_RUNTIME_OUTPUT_DIRECTORY}")
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  igi_set_warnings(${name})
  include(GoogleTest)
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 600)
  endif()
  set(props TIMEOUT ${ARG_TIMEOUT})
  if(ARG_LABELS)
    list(APPEND props LABELS "${ARG_LABELS}")
  endif()
  set(filter)
  if(ARG_TEST_FILTER)
    set(filter TEST_FILTER "${ARG_TEST_FILTER}")
  endif()
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60 ${filter} PROPERTIES ${props})
endfunction()
