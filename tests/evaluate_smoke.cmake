# The evaluation harness in its small configuration (issue "Accuracy against cost"): bench/evaluate
# --smoke runs every section on small fields, draws every chart and checks that every chart exists
# and every figure is finite (a minute or two on 2 cores). It runs the binaries the build made
# (insitu_evaluate, insitu_evaluate_vtk from bench/), so it needs the benchmarks and the examples.
if(INSITU_BUILD_BENCH AND INSITU_BUILD_EXAMPLES)
  find_program(INSITU_BASH bash)
  add_test(NAME evaluate_smoke
           COMMAND ${INSITU_BASH} ${PROJECT_SOURCE_DIR}/bench/evaluate --smoke --no-build
                   --build-dir ${PROJECT_BINARY_DIR} --out ${CMAKE_CURRENT_BINARY_DIR}/evaluate_smoke)
  set_tests_properties(evaluate_smoke PROPERTIES TIMEOUT 300)
endif()
