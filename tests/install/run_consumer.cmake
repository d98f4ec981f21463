file(REMOVE_RECURSE ${WORK_DIR})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "install failed")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -S ${CONSUMER_DIR} -B ${WORK_DIR}/build -DCMAKE_BUILD_TYPE=Release
                        -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "consumer configure failed:\n${out}\n${err}")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${WORK_DIR}/build RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "consumer build failed:\n${out}\n${err}")
endif()
execute_process(COMMAND ${WORK_DIR}/build/consumer RESULT_VARIABLE rc OUTPUT_VARIABLE out)
# The output only after the status check: the test passes on its text (PASS_REGULAR_EXPRESSION,
# which ignores the exit status), so a consumer that printed it and then failed must not show it.
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "consumer failed with status '${rc}'")
endif()
message("${out}")
# The installed Python module, when built: importable from the prefix's dist-packages alone.
if(PYTHON AND PYTHON_SITE)
  execute_process(COMMAND ${CMAKE_COMMAND} -E env PYTHONPATH=${WORK_DIR}/prefix/${PYTHON_SITE} PYTHONDONTWRITEBYTECODE=1
                          ${PYTHON} -c "import flexfit; m = flexfit.PartModel(flexfit.torus(10, 2.5, 24, 24)); print('python consumer:', m.spring_count, 'springs from', flexfit.__file__)"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT out MATCHES "python consumer: 1728 springs from ${WORK_DIR}/prefix/")
    message(FATAL_ERROR "the installed Python module failed (status '${rc}'):\n${out}\n${err}")
  endif()
  message("${out}")
endif()
