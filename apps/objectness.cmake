# Sources the objectness work adds to the sketchnav executable: target_sources(sketchnav PRIVATE ...)
target_link_libraries(sketchnav PRIVATE opencv_imgproc opencv_imgcodecs)
