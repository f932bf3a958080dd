# Sources the recognition work adds to the sketchnav executable: target_sources(sketchnav PRIVATE ...)
# cmd_train / cmd_recognise read photos and letterbox frames.
target_link_libraries(sketchnav PRIVATE opencv_imgcodecs opencv_imgproc)
