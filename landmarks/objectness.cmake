# Objectness half of the landmarks module (issue #5): CCS, SCS, their union, baselines, VOC eval.
set(LANDMARKS_OBJECTNESS_SOURCES
  ${CMAKE_CURRENT_SOURCE_DIR}/src/boxes_nms.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/voc_dataset.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/voc_metrics.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/voc_evaluate.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/baselines_methods.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/fcm_cluster.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/dbscan_cluster.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/scs_straddling.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/scs_propose.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/ccs_propose.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/objectness_propose.cpp)
set(LANDMARKS_OBJECTNESS_TESTS
  ${CMAKE_CURRENT_SOURCE_DIR}/tests/test_objectness_baselines.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/tests/test_objectness_boxes.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/tests/test_objectness_parts.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/tests/test_objectness_union.cpp)
