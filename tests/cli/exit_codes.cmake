# Runs the command with bad input and checks exit codes and the one-line message.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
include(${CMAKE_CURRENT_LIST_DIR}/../support/expect_exit.cmake)
expect(2 "unknown subcommand 'fly'" fly)
expect(2 "unknown camera URI scheme 'gopro'" probe gopro://x)
expect(2 "image folder '${WORK}/none' does not exist" probe folder://${WORK}/none)
expect(2 "config file '${WORK}/missing.json' cannot be opened" --config ${WORK}/missing.json probe folder:///x)
expect(2 "unknown option '--bogus'" probe --bogus 1 folder:///x)
expect(2 "--set 'oops': expected key=value" --set oops probe folder:///x)
# A folder with one good frame and one corrupt one: probe reports both, JSON on stdout.
file(WRITE ${WORK}/frames/b.jpg "not a jpeg")
file(COPY ${CMAKE_CURRENT_LIST_DIR}/fixtures/tiny.png DESTINATION ${WORK}/frames)
run_ok(out err --json probe folder://${WORK}/frames --frames 5)
string(JSON received GET "${out}" received)
string(JSON dropped GET "${out}" dropped)
string(JSON kind GET "${out}" kind)
if(NOT received EQUAL 1 OR NOT dropped EQUAL 1 OR NOT kind STREQUAL "camera")
  message(FATAL_ERROR "probe JSON wrong: ${out}")
endif()
if(NOT err MATCHES "WARN .*skipped unreadable frame")
  message(FATAL_ERROR "no warning for the corrupt frame: ${err}")
endif()
# Bad-input campaign (issue 28): special files, deep nesting, 1e400, impossible outputs.
file(WRITE ${WORK}/deep.json "{\"a\": [[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[1]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]}")
expect(2 "config file '${WORK}/deep.json': JSON nested deeper than 64" --config ${WORK}/deep.json probe folder:///x)
file(WRITE ${WORK}/overflow.json "{\"camera\": {\"folder\": {\"fps\": 1e400}}}")
expect(2 "config file '${WORK}/overflow.json': not valid JSON: number overflow" --config ${WORK}/overflow.json probe folder:///x)
expect(2 "config file '${WORK}': is a directory" --config ${WORK} probe folder:///x)
expect(2 "world file '${WORK}': is a directory" sim map --world ${WORK} -o ${WORK}/m.png)
expect(2 "sketchnav sim: -o '/nonexistent-sketchnav/dir/m.png': folder '/nonexistent-sketchnav/dir' does not exist" sim map -o /nonexistent-sketchnav/dir/m.png)
if(EXISTS /nonexistent-sketchnav)
  message(FATAL_ERROR "sim map -o created /nonexistent-sketchnav")
endif()
expect(2 "sketchnav train: -o '/dev/full': is a character device" train --landmarks ${WORK} -o /dev/full)
# Image inputs (issue 28): special files refused before opening (a FIFO hung `propose`), a
# header declaring 30000 x 30000 pixels refused before decoding (it decoded in 11 s and 5.4 GB),
# a truncated JPEG refused (it was accepted with a grey bottom), a text file named.
set(FX ${CMAKE_CURRENT_LIST_DIR}/fixtures)
execute_process(COMMAND mkfifo ${WORK}/fifo.jpg RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "mkfifo failed: ${rc}")
endif()
expect(2 "sketchnav propose: image '${WORK}/fifo.jpg': is a FIFO, expected a regular file"
       propose ${WORK}/fifo.jpg -o ${WORK}/p.png)
expect(2 "sketchnav propose: image '${WORK}': is a directory, expected a regular file"
       propose ${WORK} -o ${WORK}/p.png)
expect(2 "sketchnav propose: image '${FX}/bomb_30000x30000.jpg': JPEG header declares 30000 x 30000 pixels \\(900000000 > 67108864\\)"
       propose ${FX}/bomb_30000x30000.jpg -o ${WORK}/p.png)
expect(2 "sketchnav propose: image '${FX}/truncated.jpg': truncated JPEG \\(no end-of-image marker\\)"
       propose ${FX}/truncated.jpg -o ${WORK}/p.png)
file(WRITE ${WORK}/notes.png "not an image\n")
expect(2 "sketchnav propose: image '${WORK}/notes.png': not an image \\(expected JPEG, PNG"
       propose ${WORK}/notes.png -o ${WORK}/p.png)
if(EXISTS ${WORK}/p.png)
  message(FATAL_ERROR "propose wrote ${WORK}/p.png for a bad image")
endif()
# The folder camera skips a bomb frame and a truncated one with a warning naming why.
file(COPY ${FX}/tiny.png ${FX}/bomb_30000x30000.jpg ${FX}/truncated.jpg DESTINATION ${WORK}/bombs)
run_ok(out err --json probe folder://${WORK}/bombs --frames 5)
string(JSON received GET "${out}" received)
string(JSON dropped GET "${out}" dropped)
if(NOT received EQUAL 1 OR NOT dropped EQUAL 2)
  message(FATAL_ERROR "probe of a folder with a bomb and a truncated frame: ${out}")
endif()
if(NOT err MATCHES "skipped unreadable frame.*declares 30000 x 30000")
  message(FATAL_ERROR "no warning naming the bomb frame: ${err}")
endif()
# Unknown device URI parameters are errors like unknown settings (issue 28).
expect(2 "camera URI 'folder:///x\\?fsp=10': unknown parameter 'fsp' \\(did you mean 'fps'\\?\\)"
       probe folder:///x?fsp=10)
expect(2 "camera URI 'sim://lab\\?sed=3': unknown parameter 'sed' \\(did you mean 'seed'\\?\\)"
       probe sim://lab?sed=3)
# Numbers that are no number of the kind asked (issue 28): `--max-time nan` ran with the default
# time, `--set sim.seed=-1` with seed 18446744073709551615, an int option of 2^32+1 as 1.
expect(2 "sketchnav run: --max-time expects a finite number, got 'nan'" run --max-time nan --out ${WORK}/r-nan)
expect(2 "sketchnav run: --max-time expects a finite number, got 'inf'" run --max-time inf --out ${WORK}/r-inf)
expect(2 "sketchnav run: --max-time must be > 0 s" run --max-time 0 --out ${WORK}/r-zero)
expect(2 "--set sim.seed: setting 'sim.seed' must be a whole number in \\[0, 18446744073709551615\\] \\(got -1\\)"
       sim drive --world corridor --seconds 0.5 --camera-hz 0 --set sim.seed=-1 --out ${WORK}/d-seed)
expect(2 "sketchnav sim drive: --seed expects an integer in \\[-2147483648, 2147483647\\], got '4294967297'"
       sim drive --world corridor --seconds 0.5 --camera-hz 0 --seed 4294967297 --out ${WORK}/d-seed2)
