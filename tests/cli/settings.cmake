# Strict settings: a key no Params of the subcommand takes is an error (exit 2) naming the key
# and the closest known one, on --set and --config alike, before the subcommand does its work.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
include(${CMAKE_CURRENT_LIST_DIR}/../support/expect_exit.cmake)
set(LAB ${SRC}/share/sketches/lab.sketch.json)

expect(2 "unknown setting 'route.simplify_tolerence' .did you mean 'route.simplify_tolerance'"
       route ${LAB} --set route.simplify_tolerence=0.1)
run_ok(out err route ${LAB} --set route.simplify_tolerance=0.03)
expect(2 "--set servo.lamda: unknown setting 'servo.lamda' .did you mean 'servo.lambda'"
       run --set servo.lamda=0.1 --out ${WORK}/run-typo)
file(WRITE ${WORK}/typo.json "{\"nav\": {\"perception\": {\"fovae\": false}}}")
expect(2 "${WORK}/typo.json: unknown setting 'nav.perception.fovae' .did you mean 'nav.perception.fovea'"
       --config ${WORK}/typo.json run --out ${WORK}/run-typo2)
# A setting that was renamed (one name per quantity: the navigation's matching rule is
# recognise --match's) names its new key, from --config as from --set.
file(WRITE ${WORK}/moved.json "{\"nav\": {\"perception\": {\"min_inliers\": 14}}}")
expect(2 "${WORK}/moved.json: setting 'nav.perception.min_inliers' is now 'landmarks.match.min_inliers'"
       --config ${WORK}/moved.json run --out ${WORK}/run-moved)
expect(2 "unknown setting 'landmarks.match.min_inlers' .did you mean 'landmarks.match.min_inliers'"
       run --set landmarks.match.min_inlers=14 --out ${WORK}/run-moved2)
# Objectness settings reach run (a valid one passes the check; the bad value is then refused).
expect(2 "objectness.nms_iou" run --set objectness.nms_iou=7 --out ${WORK}/run-objn)
expect(2 "unknown setting 'landmarks.train.vocabulary_sise' .did you mean 'landmarks.train.vocabulary_size'"
       train --landmarks ${SRC}/share/landmarks -o ${WORK}/m.slm --set landmarks.train.vocabulary_sise=10)
expect(2 "unknown setting 'objectness.nms_iuo' .did you mean 'objectness.nms_iou'"
       propose ${CMAKE_CURRENT_LIST_DIR}/fixtures/tiny.png --set objectness.nms_iuo=0.5)
expect(2 "unknown setting 'sim.odom_slip_sdt' .did you mean 'sim.odom_slip_std'"
       sim map --world lab -o ${WORK}/map.png --set sim.odom_slip_sdt=0.1)
expect(2 "unknown setting 'base_server.watchdog' .did you mean 'base_server.watchdog_s'"
       base-emulator --port 0 --seconds 1 --set base_server.watchdog=1)
expect(2 "unknown setting 'servo.lamda' .this command takes no settings"
       ui --port 0 --set servo.lamda=0.1)
expect(2 "unknown setting 'nav.max_tme_s' .did you mean 'nav.max_time_s'"
       experiments --trials 1 --variants exp2-moved-a --out ${WORK}/exp --set nav.max_tme_s=5)
expect(2 "unknown setting 'experiments.sketch.typo'"
       experiments --trials 1 --variants exp2-moved-a --out ${WORK}/exp --set experiments.sketch.typo=1)
expect(2 "--param: unknown setting 'servo.lamda' .did you mean 'servo.lambda'"
       tune --param servo.lamda --out ${WORK}/tune)
expect(2 "unknown setting 'servo.lamda' .did you mean 'servo.lambda'"
       tune --set servo.lamda=0.4 --out ${WORK}/tune)
# A device driver's settings are checked once the device is open.
file(COPY ${CMAKE_CURRENT_LIST_DIR}/fixtures/tiny.png DESTINATION ${WORK}/frames)
expect(2 "unknown setting 'camera.folder.bogus'"
       probe folder://${WORK}/frames --frames 1 --set camera.folder.bogus=1)
expect(2 "unknown setting 'nav.bogus'" probe folder://${WORK}/frames --frames 1 --set nav.bogus=1)
