# Sources the recognition work adds to the sketchnav executable: target_sources(sketchnav PRIVATE ...)
