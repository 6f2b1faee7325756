# Every test of the project, each C++ test program with its one list of sources. Included by the
# top-level CMakeLists.txt in each of its builds, which declares a program only where the
# libraries it links are built:
#   catkin              every program below and the rostests (catkin_make run_tests); with
#                       MVOG_FUZZ_TARGETS=replay the fuzz replays too (the ASan + UBSan
#                       workspace of scripts/sanitizers.sh);
#   plain CMake         the core's (cmake -DMVOG_BUILD_ROS=OFF, ctest), and with
#                       MVOG_BUILD_ROS_CONVERSIONS those of mvog_ros_conversions too;
#   test/sanitizers     plain CMake instrumented (scripts/sanitizers.sh: TSan, and libFuzzer with
#                       the fuzz targets).

# mvog_add_gtest(NAME SOURCES file... LIBRARIES target...): a gtest program, run by catkin's
# run_tests or by ctest.
function(mvog_add_gtest name)
  cmake_parse_arguments(PARSE_ARGV 1 test "" "" "SOURCES;LIBRARIES")
  if(catkin_FOUND)
    catkin_add_gtest(${name} ${test_SOURCES})
  else()
    add_executable(${name} ${test_SOURCES})
    add_test(NAME ${name} COMMAND ${name})
  endif()
  target_link_libraries(${name} ${test_LIBRARIES} GTest::gtest GTest::gtest_main)
endfunction()

if(catkin_FOUND)
  # Nothing below is declared without CATKIN_ENABLE_TESTING: catkin_lint does not follow this
  # return(), hence its two checks of that guard are off for this file.
  #catkin_lint: ignore unguarded_test_cmd unguarded_test_depend
  if(NOT CATKIN_ENABLE_TESTING)
    return()
  endif()
else()
  include(CTest)
  if(NOT BUILD_TESTING)
    return()
  endif()
  # The core must not reach ROS, PCL, tf2 or Boost headers, not even indirectly.
  add_test(NAME core_headers_are_ros_free
    COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/test/check_core_includes.sh ${CMAKE_CXX_COMPILER}
            ${CMAKE_CURRENT_SOURCE_DIR})
endif()
find_package(GTest REQUIRED)

# ---- The core (include/mvog, src/core) ------------------------------------------------------
# Some read the recordings in $MVOG_DATA_DIR, else ../shared/data beside the sources, through
# mvog_bench's scan graph reader (ROS-free).
mvog_add_gtest(test_mvog_core
  SOURCES test/core/test_volume.cpp test/core/test_raster.cpp test/core/test_insertion.cpp
          test/core/test_queries.cpp test/core/test_map.cpp test/core/test_map_io.cpp
          test/core/test_column.cpp test/core/test_height_colour.cpp
          test/core/test_lifecycle.cpp test/core/test_merge.cpp test/core/test_map_update.cpp
          test/core/test_checks.cpp test/core/test_segment_property.cpp
          test/core/test_frontiers.cpp test/core/test_surfaces.cpp
          test/core/test_depth_image.cpp test/core/test_free_space_rays.cpp
          test/core/test_evidence_limit.cpp
          src/tools/bench/scan_graph_input.cpp
  LIBRARIES mvog_core)
target_include_directories(test_mvog_core PRIVATE src/tools/bench)
target_compile_definitions(test_mvog_core PRIVATE MVOG_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}")
# A process saving maps, killed at random moments: the file always loads (RELIABILITY.md).
mvog_add_gtest(test_save_sigkill
  SOURCES test/reliability/test_save_sigkill.cpp
  LIBRARIES mvog_core)

# ---- mvog_ros_conversions: the message conversions and the map's lock ------------------------
if(TARGET mvog_ros_conversions)
  mvog_add_gtest(test_mvog_ros_conversions
    SOURCES test/ros/test_conversions.cpp test/ros/test_writer_preferring_mutex.cpp
    LIBRARIES mvog_ros_conversions mvog_scene)
  # The core's promises about threads, and the server's lock pattern (also under TSan).
  mvog_add_gtest(test_concurrency
    SOURCES test/reliability/test_concurrency.cpp
    LIBRARIES mvog_ros_conversions)
endif()

# ---- The fuzz targets (test/fuzz): only in the sanitizer builds --------------------------------
# Each target's entry point, replayed over files by fuzz_replay_NAME (MVOG_FUZZ_TARGETS = replay)
# or run by libFuzzer as fuzz_NAME (MVOG_FUZZ_TARGETS = libfuzzer, clang).
if(MVOG_FUZZ_TARGETS)
  add_library(fuzz_map_file_entry OBJECT test/fuzz/fuzz_map_file.cpp)
  target_link_libraries(fuzz_map_file_entry PUBLIC mvog_core)
  add_library(fuzz_map_update_entry OBJECT test/fuzz/fuzz_map_update.cpp)
  target_link_libraries(fuzz_map_update_entry PUBLIC mvog_core)
  add_library(fuzz_conversions_entry OBJECT test/fuzz/fuzz_conversions.cpp)
  target_link_libraries(fuzz_conversions_entry PUBLIC mvog_ros_conversions)
  # Test programs of the sanitizer builds, not installed.
  #catkin_lint: ignore uninstalled_target
  foreach(target map_file map_update conversions)
    if(MVOG_FUZZ_TARGETS STREQUAL "libfuzzer")
      add_executable(fuzz_${target} $<TARGET_OBJECTS:fuzz_${target}_entry>)
      target_link_libraries(fuzz_${target} fuzz_${target}_entry)
      target_link_options(fuzz_${target} PRIVATE -fsanitize=fuzzer)
    else()
      add_executable(fuzz_replay_${target} test/fuzz/replay_main.cpp
                     $<TARGET_OBJECTS:fuzz_${target}_entry>)
      target_link_libraries(fuzz_replay_${target} fuzz_${target}_entry)
    endif()
  endforeach()
endif()

if(NOT catkin_FOUND)
  return()
endif()

# ---- The mapping server (include/mvog_ros, src/ros) -----------------------------------------
mvog_add_gtest(test_mvog_ros
  SOURCES test/ros/test_map_paths.cpp test/ros/test_mapper_config.cpp
          test/ros/test_visualization.cpp test/ros/test_incremental_grid.cpp
          test/ros/test_insertion_worker.cpp test/ros/test_planning_messages.cpp
  LIBRARIES mvog_ros)
# The server through its ROS interface, as node and as nodelet (test/ros/*.test).
find_package(rostest REQUIRED)
add_rostest_gtest(test_mapper_node test/ros/mapper_node.test test/ros/test_mapper_node.cpp)
target_link_libraries(test_mapper_node mvog_ros mvog_scene)
add_dependencies(test_mapper_node mvog_node)  # started by RefusedStart.*
add_rostest(test/ros/mapper_nodelet.test DEPENDENCIES test_mapper_node)
add_rostest(test/ros/decay.test DEPENDENCIES test_mapper_node)
add_rostest(test/ros/refused_start.test DEPENDENCIES test_mapper_node)
# What planners and explorers ask the server (test/ros/planning.test).
add_rostest_gtest(test_planning_node test/ros/planning.test test/ros/test_planning_node.cpp)
target_link_libraries(test_planning_node mvog_ros)
add_dependencies(test_planning_node mvog_node)
# Reliability (test/reliability, RELIABILITY.md): bad input, time jumping back, SIGKILL during
# autosaves, a sensor faster than the mapper. Each test node starts its own mvog_node.
add_rostest(test/reliability/bad_input.test DEPENDENCIES mvog_node)
add_rostest(test/reliability/time_jump.test DEPENDENCIES mvog_node)
add_rostest(test/reliability/kill_during_save.test DEPENDENCIES mvog_node)
add_rostest(test/reliability/overload.test DEPENDENCIES mvog_node)
# A map's lifetime (test/lifecycle): ~clear_box and ~merge_map, the local window, mirrors.
add_rostest(test/lifecycle/map_edits.test DEPENDENCIES mvog_node)
add_rostest(test/lifecycle/window.test DEPENDENCIES mvog_node)
add_rostest(test/lifecycle/mirror.test DEPENDENCIES mvog_node mvog_mirror)
# Replays of the recordings in $MVOG_DATA_DIR (default ../shared/data) through mapper.launch,
# checked against the data's README (test/data). Skipped without the data unless CI=true.
add_rostest(test/data/newcollege.test)
add_rostest(test/data/intel_lab.test)
add_rostest(test/data/people_stationary.test)
add_rostest(test/data/forgetting.test)
add_rostest(test/data/multi_robot.test)
add_rostest(test/data/tum.test)
add_rostest(test/data/kurt3d.test)

# ---- mvog_bench (built when OctoMap is found) -------------------------------------------------
if(TARGET mvog_bench)
  find_package(jsoncpp REQUIRED)
  mvog_add_gtest(test_mvog_bench
    SOURCES test/bench/test_bench_smoke.cpp
    LIBRARIES JsonCpp::JsonCpp ${catkin_LIBRARIES})
  target_compile_definitions(test_mvog_bench PRIVATE
    MVOG_BENCH_EXECUTABLE="$<TARGET_FILE:mvog_bench>"
    MVOG_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}")
  # Which of its Bonxai cases applies: the backend's line, or the message without it.
  if(MVOG_BENCH_HAVE_BONXAI)
    target_compile_definitions(test_mvog_bench PRIVATE MVOG_BENCH_HAVE_BONXAI=1)
  endif()
  add_dependencies(test_mvog_bench mvog_bench)
endif()

# ---- dynamic_reconfigure on the server (cfg/MapperReconfigure.cfg, RuntimeReconfigure) ----------
mvog_add_gtest(test_runtime_reconfigure
  SOURCES test/ros/test_runtime_reconfigure.cpp
  LIBRARIES mvog_ros)
add_rostest(test/ros/reconfigure.test DEPENDENCIES mvog_node)

# ---- mvog_ompl: OMPL on an mvog::Map, built when OMPL is found ----------------------------------
if(TARGET mvog_ompl)
  mvog_add_gtest(test_mvog_ompl
    SOURCES test/ompl/test_map_validity.cpp
    LIBRARIES mvog_ompl)
  add_rostest(test/ros/plan_path.test DEPENDENCIES mvog_node)
endif()
