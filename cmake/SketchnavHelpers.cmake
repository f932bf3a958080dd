# sketchnav_add_module(NAME SOURCES ... PUBLIC_LINK ... PRIVATE_LINK ...)
# One library target per module with a namespaced alias, public headers under
# <dir>/include/sketchnav/<name>/, installed and exported.
function(sketchnav_add_module name)
  cmake_parse_arguments(M "" "" "SOURCES;PUBLIC_LINK;PRIVATE_LINK" ${ARGN})
  add_library(sketchnav_${name} ${M_SOURCES})
  add_library(sketchnav::${name} ALIAS sketchnav_${name})
  set_target_properties(sketchnav_${name} PROPERTIES EXPORT_NAME ${name}
                        OUTPUT_NAME sketchnav_${name})
  target_include_directories(sketchnav_${name} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>
    PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)
  target_link_libraries(sketchnav_${name} PUBLIC ${M_PUBLIC_LINK} PRIVATE ${M_PRIVATE_LINK})
  target_compile_options(sketchnav_${name} PRIVATE -Wall -Wextra -Wno-unused-parameter)
  install(TARGETS sketchnav_${name} EXPORT sketchnavTargets
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
          RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endfunction()

# sketchnav_add_test(NAME SOURCES ... LINK ...)
# One GoogleTest executable per module; tests are discovered for CTest.
function(sketchnav_add_test name)
  if(NOT SKETCHNAV_BUILD_TESTS)
    return()
  endif()
  cmake_parse_arguments(T "" "TIMEOUT" "SOURCES;LINK;LABELS" ${ARGN})
  if(NOT T_SOURCES)
    return()
  endif()
  add_executable(${name} ${T_SOURCES})
  target_link_libraries(${name} PRIVATE ${T_LINK} sketchnav_test_support GTest::gtest_main
                        GTest::gmock)
  if(NOT T_TIMEOUT)
    set(T_TIMEOUT 300)
  endif()
  # An empty LABELS value would swallow the next keyword, so it is only passed when set.
  set(props TIMEOUT ${T_TIMEOUT} ENVIRONMENT "SKETCHNAV_SOURCE_DIR=${PROJECT_SOURCE_DIR}")
  if(T_LABELS)
    list(APPEND props LABELS "${T_LABELS}")
  endif()
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60 PROPERTIES ${props})
endfunction()
