# Sources the sim work adds to the sketchnav executable: target_sources(sketchnav PRIVATE ...)
