# sketchnav recognise's pictures, driven as a user would: --eval DIR --plot (the confusion
# matrix) and IMAGE... --annotate DIR (each image with its answer drawn), on a model of the
# shipped demo set; and the one-line errors for the options used the wrong way.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK}/eval/Tropicana-Apple-Juice ${WORK}/eval/Oatly-Oat-Milk
     ${WORK}/eval/Not-In-The-Model)
include(${CMAKE_CURRENT_LIST_DIR}/../support/expect_exit.cmake)
set(L ${SRC}/share/landmarks)
file(COPY ${L}/Tropicana-Apple-Juice/Tropicana-Apple-Juice_001.jpg
          ${L}/Tropicana-Apple-Juice/Tropicana-Apple-Juice_004.jpg
     DESTINATION ${WORK}/eval/Tropicana-Apple-Juice)
file(COPY ${L}/Oatly-Oat-Milk/Oatly-Oat-Milk_001.jpg DESTINATION ${WORK}/eval/Oatly-Oat-Milk)
file(COPY ${CMAKE_CURRENT_LIST_DIR}/fixtures/tiny.png DESTINATION ${WORK}/eval/Not-In-The-Model)

run_ok(out err --json train --landmarks ${L} -o ${WORK}/demo.slm)

# train's per-class report: classes of fewer than 3 photos are flagged (the eval folder as a set:
# 2 + 1 photos; the tiny fixture has too few keypoints and its class is dropped).
run_ok(out err --json train --landmarks ${WORK}/eval -o ${WORK}/small.slm)
string(JSON weak GET "${out}" weak_classes)
string(JSON oatly_photos GET "${out}" per_class Oatly-Oat-Milk photos)
string(JSON oatly_warning GET "${out}" per_class Oatly-Oat-Milk warnings 0)
if(NOT weak EQUAL 2 OR NOT oatly_photos EQUAL 1 OR NOT oatly_warning MATCHES "few photos")
  message(FATAL_ERROR "train per-class report: weak ${weak} (2), Oatly photos ${oatly_photos} "
                      "(1), warning '${oatly_warning}':\n${out}")
endif()

# Progress into a log file (stderr not a terminal): whole lines, one per tenth of a stage at
# most, no carriage returns piling every update onto one line.
run_ok(out err train --landmarks ${WORK}/eval -o ${WORK}/small2.slm)
string(FIND "${err}" "\r" cr)
if(NOT cr EQUAL -1 OR NOT err MATCHES "train: features 4/4\n" OR NOT err MATCHES "train: vocabulary 1/1\n")
  message(FATAL_ERROR "train progress into a file is not whole lines:\n${err}")
endif()

# PNG signature and the IHDR chunk's width and height.
function(png_size file out_w out_h)
  if(NOT EXISTS ${file})
    message(FATAL_ERROR "${file} was not written")
  endif()
  file(READ ${file} head LIMIT 24 HEX)
  string(SUBSTRING "${head}" 0 16 sig)
  if(NOT sig STREQUAL "89504e470d0a1a0a")
    message(FATAL_ERROR "${file} is not a PNG (${head})")
  endif()
  string(SUBSTRING "${head}" 32 8 w)
  string(SUBSTRING "${head}" 40 8 h)
  math(EXPR w "0x${w}")
  math(EXPR h "0x${h}")
  set(${out_w} ${w} PARENT_SCOPE)
  set(${out_h} ${h} PARENT_SCOPE)
endfunction()

run_ok(out err --json recognise --model ${WORK}/demo.slm --eval ${WORK}/eval
       --plot ${WORK}/confusion.png)
string(JSON images GET "${out}" images)
string(JSON top1 GET "${out}" top1)
string(JSON sift GET "${out}" sift_alone_cpu_ms_mean)
if(NOT images EQUAL 4 OR top1 LESS 0.99 OR NOT sift GREATER 0)
  message(FATAL_ERROR "recognise --eval: images ${images} (4), top-1 ${top1} (1 on photos it "
                      "was trained on), SIFT alone ${sift} ms (> 0):\n${out}")
endif()
# Three rows (two known classes, one not in the model): at least three 18 px cells tall below
# the column labels, and wide enough for the columns and the row labels.
png_size(${WORK}/confusion.png w h)
if(w LESS 300 OR h LESS 150)
  message(FATAL_ERROR "confusion.png is ${w} x ${h}: too small for 3 rows and their labels")
endif()

run_ok(out err recognise --model ${WORK}/demo.slm --frame 640x480 --annotate ${WORK}/annotated
       ${WORK}/eval/Tropicana-Apple-Juice/Tropicana-Apple-Juice_001.jpg
       ${WORK}/eval/Oatly-Oat-Milk/Oatly-Oat-Milk_001.jpg)
png_size(${WORK}/annotated/001_Tropicana-Apple-Juice_001.png w h)
if(NOT w EQUAL 640 OR NOT h EQUAL 480)
  message(FATAL_ERROR "annotated frame is ${w} x ${h}, expected the 640 x 480 frame")
endif()
png_size(${WORK}/annotated/002_Oatly-Oat-Milk_001.png w h)

expect(2 "--plot needs --eval" recognise --model ${WORK}/demo.slm --plot ${WORK}/x.png
       ${WORK}/eval/Oatly-Oat-Milk/Oatly-Oat-Milk_001.jpg)
expect(2 "--plot '${WORK}/x.jpg' must end in .png" recognise --model ${WORK}/demo.slm
       --eval ${WORK}/eval --plot ${WORK}/x.jpg)
expect(2 "--plot folder '${WORK}/missing' does not exist" recognise --model ${WORK}/demo.slm
       --eval ${WORK}/eval --plot ${WORK}/missing/x.png)
expect(2 "--annotate is for IMAGE" recognise --model ${WORK}/demo.slm --eval ${WORK}/eval
       --annotate ${WORK}/x)
# 1 x 4000 and 4000 x 1 photos (issue 28: an OpenCV resize assertion, exit 1) are letterboxed
# to at least 1 px and simply not recognised.
run_ok(out err --json recognise --model ${WORK}/demo.slm --frame 640x480
       ${CMAKE_CURRENT_LIST_DIR}/fixtures/thin_1x4000.png
       ${CMAKE_CURRENT_LIST_DIR}/fixtures/thin_4000x1.png)
# The same photos as they are (no --frame): the feature and colour reductions rounded them to
# 0 px (the same assertion, exit 1).
run_ok(out err --json recognise --model ${WORK}/demo.slm
       ${CMAKE_CURRENT_LIST_DIR}/fixtures/thin_1x4000.png
       ${CMAKE_CURRENT_LIST_DIR}/fixtures/thin_4000x1.png)
# Image inputs (issue 28): one bad IMAGE is exit 2 naming it (a FIFO blocked for ever, a header
# declaring 30000 x 30000 pixels decoded to gigabytes); among several it is skipped with a
# warning that says why and the others are answered.
set(FX ${CMAKE_CURRENT_LIST_DIR}/fixtures)
execute_process(COMMAND mkfifo ${WORK}/fifo.jpg RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "mkfifo failed: ${rc}")
endif()
expect(2 "sketchnav recognise: image '${WORK}/fifo.jpg': is a FIFO, expected a regular file"
       recognise --model ${WORK}/demo.slm ${WORK}/fifo.jpg)
expect(2 "sketchnav recognise: image '${FX}/bomb_30000x30000.jpg': JPEG header declares 30000 x 30000 pixels"
       recognise --model ${WORK}/demo.slm ${FX}/bomb_30000x30000.jpg)
expect(2 "sketchnav recognise: image '${FX}/truncated.jpg': truncated JPEG"
       recognise --model ${WORK}/demo.slm ${FX}/truncated.jpg)
# (exit 1: some images were not answered)
execute_process(COMMAND ${SN} --json recognise --model ${WORK}/demo.slm ${FX}/bomb_30000x30000.jpg
                        ${WORK}/fifo.jpg ${WORK}/eval/Oatly-Oat-Milk/Oatly-Oat-Milk_001.jpg
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 120)
if(NOT rc EQUAL 1)
  message(FATAL_ERROR "recognise with 2 bad images of 3: exit ${rc}, expected 1\n${err}")
endif()
if(NOT err MATCHES "skipping unreadable image.*declares 30000 x 30000" OR NOT err MATCHES "is a FIFO")
  message(FATAL_ERROR "recognise: no warnings naming the bad images:\n${err}")
endif()
string(JSON n LENGTH "${out}" results)
string(JSON unreadable GET "${out}" unreadable)
if(NOT n EQUAL 1 OR NOT unreadable EQUAL 2)
  message(FATAL_ERROR "recognise: ${n} answers (1), ${unreadable} unreadable (2):\n${out}")
endif()
