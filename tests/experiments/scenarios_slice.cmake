# A slice of the generated-scenario benchmark (issue 25), kept short: three scenarios
# generated twice must be byte-identical (seeded, reproducible) and pass the generator's checks
# (it refuses to write one that does not); two of them run 8 simulated seconds each (a run
# starts only when the run's world and sketch checks pass: a failed one exits 2 before it) and
# report the benchmark's fields; a bad world is refused with its field named.
file(REMOVE_RECURSE ${WORK})
include(${CMAKE_CURRENT_LIST_DIR}/../support/expect_exit.cmake)
foreach(copy a b)
  execute_process(COMMAND ${SN} scenarios --generate 3 --seed 7 --families corridor,office,hall
                          --out ${WORK}/${copy}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "scenarios --generate failed (${rc}):\n${out}\n${err}")
  endif()
endforeach()
foreach(name corridor-7 office-8 hall-9)
  foreach(kind world sketch scenario)
    file(SHA256 ${WORK}/a/${name}.${kind}.json ha)
    file(SHA256 ${WORK}/b/${name}.${kind}.json hb)
    if(NOT ha STREQUAL hb)
      message(FATAL_ERROR "${name}.${kind}.json differs between two generations with one seed")
    endif()
  endforeach()
endforeach()

execute_process(COMMAND ${SN} --json scenarios --generate 2 --seed 7
                        --families corridor,office --run --max-time 8 --jobs 2
                        --out ${WORK}/run
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "scenarios --run failed (${rc}):\n${out}\n${err}")
endif()
string(JSON n GET "${out}" all scenarios)
if(NOT n EQUAL 2)
  message(FATAL_ERROR "all.scenarios = ${n}, expected 2:\n${out}")
endif()
foreach(i 0 1)
  string(JSON ran GET "${out}" runs ${i} ran)
  string(JSON name GET "${out}" runs ${i} name)
  if(NOT ran)
    message(FATAL_ERROR "${name} produced no summary:\n${err}")
  endif()
  file(READ ${WORK}/run/runs/${name}/summary.json sj)
  foreach(field success executive_success at_goal collided)
    string(JSON t TYPE "${sj}" ${field})
    if(NOT t STREQUAL "BOOLEAN")
      message(FATAL_ERROR "${name}: summary.json ${field} is ${t}, expected a boolean")
    endif()
  endforeach()
  string(JSON sg TYPE "${out}" runs ${i} sketch_goal_error_m)
  if(NOT sg STREQUAL "NUMBER")
    message(FATAL_ERROR "${name}: no sketch goal error (the sketch ceiling)")
  endif()
endforeach()
foreach(f corridor office)
  string(JSON k GET "${out}" by_family ${f} scenarios)
  if(NOT k EQUAL 1)
    message(FATAL_ERROR "by_family.${f}.scenarios = ${k}, expected 1")
  endif()
endforeach()
if(NOT EXISTS ${WORK}/run/benchmark.md OR NOT EXISTS ${WORK}/run/benchmark.json)
  message(FATAL_ERROR "no benchmark report")
endif()

# Turns reversed on the spot: counted from the telemetry, per run and in all. A telemetry
# written by hand (and the report made again from the kept runs): standing, left, right, left
# (2), driving (a new stand), right, a slow left that does not count, left (1): 3.
string(JSON name0 GET "${out}" runs 0 name)
string(JSON name1 GET "${out}" runs 1 name)
file(STRINGS ${WORK}/run/runs/${name0}/telemetry.csv tel LIMIT_COUNT 1)
set(rows "${tel}\n")
set(k 0)
foreach(vw "0 0.8" "0 -0.8" "0.02 0.8" "0.3 0" "0 -0.8" "0 0.1" "0 0.8")
  separate_arguments(vw)
  list(GET vw 0 v)
  list(GET vw 1 w)
  math(EXPR k "${k} + 1")
  string(APPEND rows "0.${k},0,0,0,1,1,0,${v},${w},,avoid,Straight,0,,1\n")
endforeach()
file(WRITE ${WORK}/run/runs/${name0}/telemetry.csv "${rows}")
execute_process(COMMAND ${SN} --json scenarios --generate 2 --seed 7
                        --families corridor,office --run --reuse --max-time 8 --jobs 2
                        --out ${WORK}/run
                RESULT_VARIABLE rc OUTPUT_VARIABLE out2 ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "scenarios --run --reuse failed (${rc}):\n${out2}\n${err}")
endif()
string(JSON r0 GET "${out2}" runs 0 turn_reversals)
string(JSON r1 GET "${out2}" runs 1 turn_reversals)
string(JSON rall GET "${out2}" all turn_reversals)
math(EXPR rsum "${r0} + ${r1}")
if(NOT r0 EQUAL 3 OR NOT rall EQUAL rsum)
  message(FATAL_ERROR "turn_reversals: ${name0} ${r0} (expected 3), ${name1} ${r1}, all ${rall}")
endif()

# Bad input: exit 2 with the field named.
expect(2 "unknown family 'castle'" scenarios --generate 2 --families castle --out ${WORK}/e)
expect(2 "--generate must be in" scenarios --generate 0 --out ${WORK}/e)
file(WRITE ${WORK}/bad.world.json [=[
{"floor": [[0, 0], [6, 0], [6, 4], [0, 4]],
 "walls": [{"name": "south", "from": [0, 0], "to": [6, 0]}],
 "landmarks": [{"id": "L1", "class": "Oatly-Oat-Milk",
   "texture": "textures/Oatly-Oat-Milk/Oatly-Oat-Milk_Iconic.jpg",
   "position": [3, 0.02], "yaw_deg": 90}],
 "start": {"x": 1, "y": 2}, "goal": {"x": 5, "y": 2}}
]=])
expect(2 "bad.world.json: landmarks\\[0\\].position: 'L1' is 0.03 m inside walls\\[0\\] \\('south'\\)"
       sim map --world ${WORK}/bad.world.json -o ${WORK}/bad.png)
# The run's own checks, before anything moves: a landmark class the model does not know, and a
# start heading the sketch contradicts (turned round), each exit 2 naming the field.
file(READ ${WORK}/a/corridor-7.world.json wj)
string(JSON cls SET "${wj}" landmarks 0 class "\"Nope-Juice\"")
file(WRITE ${WORK}/bad-class.world.json "${cls}")
expect(2 "bad-class.world.json: landmarks\\[0\\].class: 'Nope-Juice' is not in the landmark set"
       run --world ${WORK}/bad-class.world.json --sketch ${WORK}/a/corridor-7.sketch.json
       --max-time 1 --out ${WORK}/bad-class)
string(JSON yaw GET "${wj}" start yaw_deg)
string(REGEX REPLACE "\\..*" "" yaw "${yaw}")  # math() is integer only
math(EXPR back "${yaw} + 180" OUTPUT_FORMAT DECIMAL)
string(JSON turned SET "${wj}" start yaw_deg "${back}")
file(WRITE ${WORK}/turned.world.json "${turned}")
expect(2 "turned.world.json: start.yaw_deg: .* disagrees with the sketch"
       run --world ${WORK}/turned.world.json --sketch ${WORK}/a/corridor-7.sketch.json
       --max-time 1 --out ${WORK}/turned)
