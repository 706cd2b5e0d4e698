# cmake -DCOMMAND="prog;args" -DEXPECT="regex" -P ExpectFailure.cmake
# Passes when the command exits non-zero and its stderr is one line matching EXPECT.
execute_process(COMMAND ${COMMAND} RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(code EQUAL 0)
    message(FATAL_ERROR "expected a non-zero exit from '${COMMAND}', got 0")
endif()
string(STRIP "${err}" line)
if(line MATCHES "\n")
    message(FATAL_ERROR "expected a one-line error, got:\n${err}")
endif()
if(NOT line MATCHES "${EXPECT}")
    message(FATAL_ERROR "error '${line}' does not match '${EXPECT}'")
endif()
