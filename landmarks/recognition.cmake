# Recognition half of sketchnav::landmarks (issue #6): RootSIFT, vocabulary, BoW classifier,
# landmark set, model file, matcher, recognition.
set(LANDMARKS_RECOGNITION_SOURCES
  ${CMAKE_CURRENT_SOURCE_DIR}/src/rootsift_features.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/colour_layout.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/vocab_vocabulary.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/bow_classifier.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/landmark_set_scan.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/model_train.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/model_io.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/matcher_match.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/recognition_recognise.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/recognition_appearance.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/photo_hash.cpp)
set(LANDMARKS_RECOGNITION_TESTS
  ${CMAKE_CURRENT_SOURCE_DIR}/tests/test_recognition_rootsift.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/tests/test_recognition_model.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/tests/test_recognition_match.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/tests/test_recognition_grocery.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/tests/test_recognition_colour.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/tests/test_recognition_sibling.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/tests/test_photo_hash.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/tests/test_bad_input.cpp)
