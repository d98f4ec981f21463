# The viewer's scripted run gives the same assembly events as `flexfit run` on the same scene:
# -DRUN=flexfit -DVIEWER=flexfit-viewer -DSCENE=file -DSECONDS=s (a multiple of 1/60 s).
math(EXPR frames "${SECONDS} * 60")
execute_process(COMMAND ${RUN} run ${SCENE} --duration ${SECONDS} OUTPUT_VARIABLE run_out RESULT_VARIABLE run_status)
execute_process(COMMAND ${VIEWER} ${SCENE} --egl --frames ${frames} OUTPUT_VARIABLE viewer_out ERROR_VARIABLE viewer_err
                RESULT_VARIABLE viewer_status)
if(NOT run_status EQUAL 0 OR NOT viewer_status EQUAL 0)
  message(FATAL_ERROR "flexfit run: ${run_status}; flexfit-viewer: ${viewer_status} ${viewer_err}")
endif()
string(REGEX MATCHALL "assembled: [^\n]*" run_events "${run_out}")
string(REGEX MATCHALL "assembled: [^\n]*" viewer_events "${viewer_out}")
if(NOT run_events)
  message(FATAL_ERROR "flexfit run reported no assembly event:\n${run_out}")
endif()
if(NOT run_events STREQUAL viewer_events)
  message(FATAL_ERROR "events differ\nflexfit run:    ${run_events}\nflexfit-viewer: ${viewer_events}")
endif()
message(STATUS "same events: ${viewer_events}")
