# Region-of-attraction campaigns: the `roa` CLI over the core's engine, tests, benchmark.

target_sources(variational_formation_tools PRIVATE src/tools/roa_cli.cpp)
vf_add_tool(roa src/tools/roa_main.cpp)
vf_add_gtest(test_roa test/roa/test_roa.cpp variational_formation_tools)

find_package(benchmark QUIET)
if(benchmark_FOUND)
  add_executable(benchmark_roa benchmark/benchmark_roa.cpp)
  target_link_libraries(benchmark_roa ${variational_formation_core_LIBRARIES} benchmark::benchmark)
  target_compile_options(benchmark_roa PRIVATE ${VF_FLAGS})
  target_compile_definitions(benchmark_roa PRIVATE VF_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  # One integrator step on a 1000-agent ring, no output (the force model's cost in simulate).
  add_executable(benchmark_integrators benchmark/benchmark_integrators.cpp)
  target_link_libraries(benchmark_integrators ${variational_formation_core_LIBRARIES} benchmark::benchmark)
  target_compile_options(benchmark_integrators PRIVATE ${VF_FLAGS})
endif()
