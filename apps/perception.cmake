# The perception benchmark (issue 23 item 4): `replay --make-sequences` / `--truth` / `--eval`
# (apps/perception_bench.*, doc/perception-benchmark.md).
target_sources(sketchnav PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/perception_bench.cpp)
