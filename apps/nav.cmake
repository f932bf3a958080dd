# Sources the nav work adds to the sketchnav executable: target_sources(sketchnav PRIVATE ...)
# `sketchnav run` as a function, the run folder, the judge and the experiment model are the run
# library (run/: sketchnav::run), which the closed-loop integration tests link too.
target_link_libraries(sketchnav PRIVATE sketchnav::run)
