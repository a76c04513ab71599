# Smoke tests of the example programs (included from examples/CMakeLists.txt when
# tests are on): each program runs briefly on a small grid, --help works, bad flags
# fail, CSV headers are exact, and moving_box's pass/fail exit code is honoured.
# Total run time: well under two minutes on a 2-core machine.

set(_ex_out ${CMAKE_CURRENT_BINARY_DIR}/test_output)
file(MAKE_DIRECTORY ${_ex_out})

# Helper script: run a program, require exit code 0, then require that the first
# line of the CSV named OUT equals HEADER and that it has ROWS data rows.
set(_ex_check ${CMAKE_CURRENT_BINARY_DIR}/run_and_check_csv.cmake)
file(WRITE ${_ex_check} [=[
file(REMOVE ${OUT})
string(REPLACE "|" ";" ARGS "${ARGS}")
execute_process(COMMAND ${PROGRAM} ${ARGS} --out ${OUT} RESULT_VARIABLE rc
                OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("${out}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${PROGRAM} exited with ${rc}:\n${err}")
endif()
if(NOT EXISTS ${OUT})
  message(FATAL_ERROR "${PROGRAM} wrote no ${OUT}")
endif()
file(STRINGS ${OUT} lines)
list(LENGTH lines n)
list(GET lines 0 first)
if(NOT first STREQUAL HEADER)
  message(FATAL_ERROR "${OUT}: header '${first}', expected '${HEADER}'")
endif()
math(EXPR rows "${n} - 1")
if(NOT rows EQUAL ROWS)
  message(FATAL_ERROR "${OUT}: ${rows} data rows, expected ${ROWS}")
endif()
if(DEFINED EXPECT AND NOT out MATCHES "${EXPECT}")
  message(FATAL_ERROR "output does not match '${EXPECT}'")
endif()
]=])

# parafsi_example_csv_test(NAME PROGRAM HEADER ROWS EXPECT args...)
function(parafsi_example_csv_test name program header rows expect)
  list(JOIN ARGN "|" _args)  # passed as one -D value, split again by the script
  add_test(NAME ${name}
    COMMAND ${CMAKE_COMMAND} -DPROGRAM=$<TARGET_FILE:${program}> "-DARGS=${_args}"
            -DOUT=${_ex_out}/${name}.csv "-DHEADER=${header}" -DROWS=${rows} "-DEXPECT=${expect}"
            -P ${_ex_check})
  set_tests_properties(${name} PROPERTIES TIMEOUT 120 LABELS examples)
endfunction()

# parafsi_example_test(NAME PROGRAM args...): exit code 0.
function(parafsi_example_test name program)
  add_test(NAME ${name} COMMAND ${program} ${ARGN})
  set_tests_properties(${name} PROPERTIES TIMEOUT 120 LABELS examples)
endfunction()

# parafsi_example_fails(NAME PROGRAM args...): must exit non-zero.
function(parafsi_example_fails name program)
  add_test(NAME ${name} COMMAND ${program} ${ARGN})
  set_tests_properties(${name} PROPERTIES WILL_FAIL TRUE TIMEOUT 60 LABELS examples)
endfunction()

# Bad flags on otherwise valid command lines (moving_box takes no --out).
foreach(prog IN ITEMS shock_tube isentropic_vortex gresho_vortex moving_box)
  set(out --out ${_ex_out}/unused.csv)
  if(prog STREQUAL "moving_box")
    set(out --steps 10)
  endif()
  parafsi_example_test(example_${prog}_help ${prog} --help)
  parafsi_example_fails(example_${prog}_unknown_flag ${prog} --no-such-flag 1 ${out})
  parafsi_example_fails(example_${prog}_bad_flux ${prog} --flux foo ${out})
  parafsi_example_fails(example_${prog}_bad_limiter ${prog} --limiter superbee ${out})
  parafsi_example_fails(example_${prog}_zero_cells ${prog} --cells 0 ${out})
  parafsi_example_fails(example_${prog}_bad_cfl ${prog} --cfl 1.5 ${out})
endforeach()

# ---- shock_tube: every problem, flux, limiter and axis at least once (100 cells).
parafsi_example_csv_test(example_shock_tube_sod shock_tube "x,rho,u,p" 100 "l1_rho="
  --problem sod --flux hllc_lm --limiter van_leer --cells 100 --axis x)
parafsi_example_csv_test(example_shock_tube_lax shock_tube "x,rho,u,p" 100 "l1_rho="
  --problem lax --flux hllc --limiter minmod --cells 100 --axis y)
parafsi_example_csv_test(example_shock_tube_toro2 shock_tube "x,rho,u,p" 100 "l1_rho="
  --problem toro2 --flux rusanov --limiter mc --cells 100 --axis z)
parafsi_example_csv_test(example_shock_tube_toro3 shock_tube "x,rho,u,p" 100 "l1_rho="
  --problem toro3 --flux ausm_plus_up --limiter none --cells 100 --axis x)
parafsi_example_csv_test(example_shock_tube_t_end shock_tube "x,rho,u,p" 50 "t_end=0.05"
  --problem sod --cells 50 --axis y --t-end 0.05)
parafsi_example_fails(example_shock_tube_bad_problem shock_tube --problem toro9 --out ${_ex_out}/unused.csv)
parafsi_example_fails(example_shock_tube_bad_axis shock_tube --axis w --out ${_ex_out}/unused.csv)
parafsi_example_fails(example_shock_tube_no_out shock_tube --problem sod)
parafsi_example_fails(example_shock_tube_negative_t_end shock_tube --t-end -1 --out ${_ex_out}/unused.csv)

# ---- isentropic_vortex: one period on 16 x 16 (and a low-Mach variant).
parafsi_example_csv_test(example_isentropic_vortex isentropic_vortex "x,y,rho,u,v,p" 256 "l1_density_error="
  --cells 16)
parafsi_example_csv_test(example_isentropic_vortex_mach isentropic_vortex "x,y,rho,u,v,p" 256 "l1_density_error="
  --cells 16 --mach 0.5 --flux ausm_plus_up --limiter mc --t-end 2)
parafsi_example_fails(example_isentropic_vortex_bad_mach isentropic_vortex --mach 0 --out ${_ex_out}/unused.csv)
parafsi_example_fails(example_isentropic_vortex_no_out isentropic_vortex --cells 16)

# ---- gresho_vortex: 16 x 16, short run.
parafsi_example_csv_test(example_gresho_vortex gresho_vortex "x,y,rho,u,v,p" 256 "kinetic_energy_ratio="
  --mach 0.1 --cells 16 --t-end 0.1)
parafsi_example_csv_test(example_gresho_vortex_hllc gresho_vortex "x,y,rho,u,v,p" 256 "kinetic_energy_ratio="
  --mach 0.01 --cells 16 --flux hllc --t-end 0.01)
parafsi_example_fails(example_gresho_vortex_bad_mach gresho_vortex --mach -0.1 --cells 16 --out ${_ex_out}/unused.csv)
parafsi_example_fails(example_gresho_vortex_bad_t_end gresho_vortex --t-end abc --out ${_ex_out}/unused.csv)

# ---- moving_box: the default run (16^3, 10^4 steps) must pass; other fluxes briefly;
#      an impossible tolerance must make it exit non-zero.
parafsi_example_test(example_moving_box moving_box)
set_tests_properties(example_moving_box PROPERTIES PASS_REGULAR_EXPRESSION "free_stream_preservation=PASS")
foreach(f IN ITEMS hllc rusanov ausm_plus_up)
  parafsi_example_test(example_moving_box_${f} moving_box --flux ${f} --limiter mc --cells 8 --steps 500)
endforeach()
parafsi_example_fails(example_moving_box_detects_failure moving_box --cells 8 --steps 50 --tolerance 1e-300)
parafsi_example_fails(example_moving_box_bad_steps moving_box --steps 0)
# ---- inflated_membrane: both membrane elements on a coarse disk (N = 6 → 7 radii).
parafsi_example_csv_test(example_inflated_membrane_tri inflated_membrane "r,w" 7 "centre_deflection="
  --radius 0.5 --thickness 1e-4 --E 1e9 --nu 0.3 --pressure 40 --elements 6)
parafsi_example_csv_test(example_inflated_membrane_quad inflated_membrane "r,w" 7 "centre_deflection="
  --radius 0.5 --thickness 1e-4 --E 1e9 --nu 0.3 --pressure 40 --elements 6 --element quad)
parafsi_example_fails(example_inflated_membrane_bad_element inflated_membrane --radius 0.5 --thickness 1e-4
  --E 1e9 --nu 0.3 --pressure 40 --element hex --out ${_ex_out}/unused.csv)

# ---- drop_guide (docs/guide_drop.md): the coupled drop on its tiny grid for 0.05 s.
#      --out names a directory: history.csv (header exact, one row per 5 ms and the start)
#      and summary.csv (header exact, one row).
# Helper script: run PROGRAM ARGS --out DIR, require exit code 0 and the output to match
# EXPECT; CSVS, HEADERS and ROWS are |-separated lists of the same length: DIR/CSVS[i]
# must start with the line HEADERS[i] and have ROWS[i] data rows.
set(_ex_dir_check ${CMAKE_CURRENT_BINARY_DIR}/run_and_check_dir.cmake)
file(WRITE ${_ex_dir_check} [=[
file(REMOVE_RECURSE ${OUT})
string(REPLACE "|" ";" ARGS "${ARGS}")
execute_process(COMMAND ${PROGRAM} ${ARGS} --out ${OUT} RESULT_VARIABLE rc
                OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("${out}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${PROGRAM} exited with ${rc}:\n${err}")
endif()
if(NOT out MATCHES "${EXPECT}")
  message(FATAL_ERROR "output does not match '${EXPECT}'")
endif()
string(REPLACE "|" ";" CSVS "${CSVS}")
string(REPLACE "|" ";" HEADERS "${HEADERS}")
string(REPLACE "|" ";" ROWS "${ROWS}")
foreach(csv header rows IN ZIP_LISTS CSVS HEADERS ROWS)
  if(NOT EXISTS ${OUT}/${csv})
    message(FATAL_ERROR "${PROGRAM} wrote no ${OUT}/${csv}")
  endif()
  file(STRINGS ${OUT}/${csv} lines)
  list(LENGTH lines n)
  list(GET lines 0 first)
  if(NOT first STREQUAL header)
    message(FATAL_ERROR "${OUT}/${csv}: header '${first}', expected '${header}'")
  endif()
  math(EXPR got "${n} - 1")
  if(NOT got EQUAL rows)
    message(FATAL_ERROR "${OUT}/${csv}: ${got} data rows, expected ${rows}")
  endif()
endforeach()
]=])

# parafsi_example_dir_test(NAME PROGRAM CSVS HEADERS ROWS EXPECT args...), lists |-separated.
function(parafsi_example_dir_test name program csvs headers rows expect)
  list(JOIN ARGN "|" _args)
  add_test(NAME ${name}
    COMMAND ${CMAKE_COMMAND} -DPROGRAM=$<TARGET_FILE:${program}> "-DARGS=${_args}" -DOUT=${_ex_out}/${name}
            "-DCSVS=${csvs}" "-DHEADERS=${headers}" "-DROWS=${rows}" "-DEXPECT=${expect}" -P ${_ex_dir_check})
  set_tests_properties(${name} PROPERTIES TIMEOUT 120 LABELS examples ENVIRONMENT "OMP_NUM_THREADS=1")
endfunction()

parafsi_example_dir_test(example_drop_guide drop_guide "history.csv|summary.csv"
  "t,x,y,z,vx,vy,vz,speed,canopy_diameter,open_force,payload_phi_x,payload_phi_y,canopy_phi_x,canopy_phi_y,flight_path_angle,drag_coefficient,open_force_filtered|fabric,t_f,t_mo,t_p,F_p,v_terminal,cd_terminal,attitude_amplitude,descent_mode"
  "11|1" "rows=11 t=0\\.0500 s" --t-end 0.05)
parafsi_example_test(example_drop_guide_help drop_guide --help)
parafsi_example_fails(example_drop_guide_bad_t_end drop_guide --t-end -1 --out ${_ex_out}/unused_drop_guide)

# ---- parachute_drop: the tiny grid for 20 ms with pressure-gradient scaling; bad flags.
parafsi_example_dir_test(example_parachute_drop_tiny_pgs parachute_drop "history.csv|summary.csv"
  "t,x,y,z,vx,vy,vz,speed,canopy_diameter,open_force,payload_phi_x,payload_phi_y,canopy_phi_x,canopy_phi_y,flight_path_angle,drag_coefficient,open_force_filtered|fabric,t_f,t_mo,t_p,F_p,v_terminal,cd_terminal,attitude_amplitude,descent_mode"
  "5|1" "fabric,t_f,t_mo" --resolution tiny --t-end 0.02 --pgs 4 --slice-times 0.01 --quiet)
# The method's mixing-length closure (distance to the canopy and lines refreshed every step).
parafsi_example_dir_test(example_parachute_drop_tiny_mixing_length parachute_drop "summary.csv"
  "fabric,t_f,t_mo,t_p,F_p,v_terminal,cd_terminal,attitude_amplitude,descent_mode"
  "1" "fabric,t_f,t_mo" --resolution tiny --t-end 0.02 --closure mixing_length --quiet)
# The embedded coupling with first-order cells beside the cloth (the default is one-sided on the box).
parafsi_example_dir_test(example_parachute_drop_tiny_first_order parachute_drop "summary.csv"
  "fabric,t_f,t_mo,t_p,F_p,v_terminal,cd_terminal,attitude_amplitude,descent_mode"
  "1" "fabric,t_f,t_mo" --resolution tiny --t-end 0.02 --membrane-reconstruction first_order --quiet)
# The block mesh (penalty coupling): the tiny scene for 20 ms, history, summary, a slice, VTK.
parafsi_example_dir_test(example_parachute_drop_tiny_blocks parachute_drop "history.csv|summary.csv|slice_00.010.csv"
  "t,x,y,z,vx,vy,vz,speed,canopy_diameter,open_force,payload_phi_x,payload_phi_y,canopy_phi_x,canopy_phi_y,flight_path_angle,drag_coefficient,open_force_filtered|fabric,t_f,t_mo,t_p,F_p,v_terminal,cd_terminal,attitude_amplitude,descent_mode|xi,zeta,x,y,z,rho,p,speed,speed_rel,omega_n"
  "5|1|1280" "fabric,t_f,t_mo" --resolution tiny --t-end 0.02 --mesh blocks --coupling penalty --block-size 4
  --slice-times 0.01 --vtk-every 0.01 --quiet)
# The block mesh with the embedded coupling (the default coupling): the tiny scene for 20 ms
# with its mesh.csv (regridding every 5 steps: the first mesh and the regrid at step 10 that
# changed it; with the default regrid every step the tighter buffer keeps the first mesh for 20 ms).
parafsi_example_dir_test(example_parachute_drop_tiny_blocks_embedded parachute_drop "history.csv|summary.csv|mesh.csv"
  "t,x,y,z,vx,vy,vz,speed,canopy_diameter,open_force,payload_phi_x,payload_phi_y,canopy_phi_x,canopy_phi_y,flight_path_angle,drag_coefficient,open_force_filtered|fabric,t_f,t_mo,t_p,F_p,v_terminal,cd_terminal,attitude_amplitude,descent_mode|t,step,blocks,cells,cells_level_0,cells_level_1"
  "5|1|2" "fabric,t_f,t_mo" --resolution tiny --t-end 0.02 --mesh blocks --block-size 4 --refine-every 5 --quiet)
# ... with the wake criterion (runs; the 20 ms wake stays inside the canopy's buffer: the mesh.csv rows of the plain run) ...
parafsi_example_dir_test(example_parachute_drop_tiny_blocks_vorticity parachute_drop "summary.csv|mesh.csv"
  "fabric,t_f,t_mo,t_p,F_p,v_terminal,cd_terminal,attitude_amplitude,descent_mode|t,step,blocks,cells,cells_level_0,cells_level_1"
  "1|2" "fabric,t_f,t_mo" --resolution tiny --t-end 0.02 --mesh blocks --block-size 4 --refine-every 5 --refine-vorticity 0.02 --quiet)
# ... with the mixing-length closure (the wall distance on every block's cells and ghosts) ...
parafsi_example_dir_test(example_parachute_drop_tiny_blocks_mixing_length parachute_drop "summary.csv|mesh.csv"
  "fabric,t_f,t_mo,t_p,F_p,v_terminal,cd_terminal,attitude_amplitude,descent_mode|t,step,blocks,cells,cells_level_0,cells_level_1"
  "1|2" "fabric,t_f,t_mo" --resolution tiny --t-end 0.02 --mesh blocks --block-size 4 --refine-every 5 --turbulence mixing_length --quiet)
# ... and with the air's laminar viscosity.
parafsi_example_dir_test(example_parachute_drop_tiny_blocks_viscous parachute_drop "history.csv|summary.csv"
  "t,x,y,z,vx,vy,vz,speed,canopy_diameter,open_force,payload_phi_x,payload_phi_y,canopy_phi_x,canopy_phi_y,flight_path_angle,drag_coefficient,open_force_filtered|fabric,t_f,t_mo,t_p,F_p,v_terminal,cd_terminal,attitude_amplitude,descent_mode"
  "5|1" "fabric,t_f,t_mo" --resolution tiny --t-end 0.02 --mesh blocks --block-size 4 --viscosity constant --quiet)
# The embedded coupling with the fabric law on each face's velocity (the rule before 2026-12).
parafsi_example_dir_test(example_parachute_drop_tiny_through_flow_face parachute_drop "summary.csv"
  "fabric,t_f,t_mo,t_p,F_p,v_terminal,cd_terminal,attitude_amplitude,descent_mode"
  "1" "fabric,t_f,t_mo" --resolution tiny --t-end 0.02 --through-flow face --quiet)
parafsi_example_fails(example_parachute_drop_bad_through_flow parachute_drop --through-flow normal --out ${_ex_out}/unused_drop)
# drop_readout recomputes that run's summary from its history.csv: the same row, byte for byte
# (the history's numbers read back exactly; the window rules are test_drop_summary's).
set_tests_properties(example_parachute_drop_tiny_pgs PROPERTIES FIXTURES_SETUP tiny_drop_history)
add_test(NAME example_drop_readout_same_summary
  COMMAND ${CMAKE_COMMAND} -E chdir ${_ex_out} sh -c
          "'$<TARGET_FILE:drop_readout>' --history example_parachute_drop_tiny_pgs/history.csv --fabric mat544 --history-every 0.005 --out drop_readout_summary.csv && '${CMAKE_COMMAND}' -E compare_files drop_readout_summary.csv example_parachute_drop_tiny_pgs/summary.csv")
set_tests_properties(example_drop_readout_same_summary PROPERTIES FIXTURES_REQUIRED tiny_drop_history TIMEOUT 60
  LABELS examples)
parafsi_example_test(example_drop_readout_help drop_readout --help)
parafsi_example_fails(example_drop_readout_no_history drop_readout --history ${_ex_out}/no_such_history.csv
  --out ${_ex_out}/unused_readout.csv)
parafsi_example_test(example_parachute_drop_help parachute_drop --help)
parafsi_example_fails(example_parachute_drop_bad_pgs parachute_drop --pgs 0.5 --out ${_ex_out}/unused_drop)
parafsi_example_fails(example_parachute_drop_bad_slice_times parachute_drop --slice-times 0.5,abc --out ${_ex_out}/unused_drop)
parafsi_example_fails(example_parachute_drop_bad_fabric parachute_drop --fabric nylon --out ${_ex_out}/unused_drop)

# ---- parachute_drop refusals (exit code non-zero and the message naming the cause).
# Helper script: optionally make OUT a directory whose FULL entry (a |-list of names) are
# links to /dev/full (a device that accepts the open and fails every write with ENOSPC),
# run PROGRAM ARGS --out OUT, require a non-zero exit code and the output (stdout and
# stderr) to match EXPECT. ARGS without --out get --out OUT.
set(_ex_fail_check ${CMAKE_CURRENT_BINARY_DIR}/run_and_expect_failure.cmake)
file(WRITE ${_ex_fail_check} [=[
file(REMOVE_RECURSE ${OUT})
if(DEFINED FULL AND NOT FULL STREQUAL "")
  if(NOT EXISTS /dev/full)
    message("no /dev/full on this system: skipped")
    return()
  endif()
  file(MAKE_DIRECTORY ${OUT})
  string(REPLACE "|" ";" FULL "${FULL}")
  foreach(name IN LISTS FULL)
    file(CREATE_LINK /dev/full ${OUT}/${name} SYMBOLIC)
  endforeach()
endif()
string(REPLACE "|" ";" ARGS "${ARGS}")
if(NOT ARGS MATCHES "(^|;)--out(;|$)")
  list(APPEND ARGS --out ${OUT})
endif()
execute_process(COMMAND ${PROGRAM} ${ARGS} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("${err}")
if(rc EQUAL 0)
  message(FATAL_ERROR "${PROGRAM} exited with 0 where it must fail")
endif()
if(NOT "${out}${err}" MATCHES "${EXPECT}")
  message(FATAL_ERROR "the message does not match '${EXPECT}'")
endif()
]=])

# parafsi_example_refuses(NAME PROGRAM FULL EXPECT args...): FULL a |-list of files linked
# to /dev/full in the output directory ("" for none).
function(parafsi_example_refuses name program full expect)
  list(JOIN ARGN "|" _args)
  add_test(NAME ${name}
    COMMAND ${CMAKE_COMMAND} -DPROGRAM=$<TARGET_FILE:${program}> "-DARGS=${_args}" -DOUT=${_ex_out}/${name}
            "-DFULL=${full}" "-DEXPECT=${expect}" -P ${_ex_fail_check})
  set_tests_properties(${name} PROPERTIES TIMEOUT 60 LABELS examples ENVIRONMENT "OMP_NUM_THREADS=1")
endfunction()

# Write failures: history.csv or summary.csv on a full device, an --out that cannot be a
# directory, a history.csv that is a directory.
parafsi_example_refuses(example_parachute_drop_history_full parachute_drop "history.csv"
  "cannot write '[^']*history\\.csv': No space left on device" --resolution tiny --t-end 0.01 --quiet)
parafsi_example_refuses(example_parachute_drop_summary_full parachute_drop "summary.csv"
  "cannot write '[^']*summary\\.csv': No space left on device" --resolution tiny --t-end 0.01 --quiet)
parafsi_example_refuses(example_parachute_drop_slice_full parachute_drop "slice_00.000.csv"
  "cannot write '[^']*slice_00\\.000\\.csv': No space left on device" --resolution tiny --t-end 0.01 --quiet
  --slice-times 0)
parafsi_example_refuses(example_parachute_drop_out_not_a_directory parachute_drop "" "Not a directory"
  --resolution tiny --t-end 0.01 --quiet --out /dev/full/x)
# Non-finite values of every floating flag, named by the flag.
foreach(flag IN ITEMS t-end history-every force-cutoff box-width box-length box-ahead growth cell element cfl pfac stiffening
                      coupling-damping membrane-damping initial-speed impedance payload-mass line-stiffness
                      modulus-scale packed-parameter fixed-fall pgs vtk-every checkpoint-every)
  parafsi_example_refuses(example_parachute_drop_nan_${flag} parachute_drop ""
    "--${flag}: value nan is not a finite number" --${flag} nan)
endforeach()
parafsi_example_refuses(example_parachute_drop_inf_t_end parachute_drop "" "--t-end: value inf is not a finite number"
  --t-end inf)
# The block mesh's limits, named.
parafsi_example_refuses(example_parachute_drop_turbulence_inviscid parachute_drop ""
  "cannot run with --viscosity inviscid" --turbulence mixing_length --viscosity inviscid)
parafsi_example_refuses(example_parachute_drop_vorticity_tensor parachute_drop "" "--refine-vorticity needs --mesh blocks"
  --refine-vorticity 0.1)
parafsi_example_refuses(example_parachute_drop_column_tensor parachute_drop "" "--refine-column needs --mesh blocks"
  --refine-column)
parafsi_example_refuses(example_parachute_drop_blocks_odd_size parachute_drop "" "--block-size must be even"
  --mesh blocks --coupling penalty --block-size 5)
# The bundle's mouth diameter outside [0.01, 0.5] D0 (a smaller one would leave elements of ≈ d/D0 of their area).
parafsi_example_refuses(example_parachute_drop_bundle_mouth_small parachute_drop ""
  "--packed-parameter 0: the bundle's mouth diameter d/D0 must be in \\[0\\.01, 0\\.5\\]"
  --resolution tiny --t-end 0.01 --quiet --packed bundle --packed-parameter 0)
parafsi_example_refuses(example_parachute_drop_bundle_mouth_large parachute_drop ""
  "--packed-parameter 0\\.75: the bundle's mouth diameter d/D0 must be in \\[0\\.01, 0\\.5\\]"
  --resolution tiny --t-end 0.01 --quiet --packed bundle --packed-parameter 0.75)
# Counts from doubles: refused before anything is cast or allocated, naming the count.
parafsi_example_refuses(example_parachute_drop_tiny_cell parachute_drop "" "would have more than 1e308 cells"
  --cell 1e-300)
parafsi_example_refuses(example_parachute_drop_huge_grid parachute_drop "" "would have about [0-9.e+]+ cells"
  --cell 1e-3)
parafsi_example_refuses(example_parachute_drop_tiny_element parachute_drop "" "would give more than 1e308 triangles"
  --element 1e-300)

# ---- Every program that writes: a file on a full device (/dev/full accepts the open and
# fails every write with ENOSPC) and a path under a regular file (refused at the open,
# also for root, which a read-only directory would not stop) exit non-zero naming the
# file and the system's reason.
set(_ex_writers
  "bluff_body_drag|--cells|4|--time|2e-4|--quiet"
  "gresho_vortex|--cells|8|--t-end|0.01|--quiet"
  "isentropic_vortex|--cells|8|--t-end|0.01|--quiet"
  "leak_box|--cells|10|--time|1e-4|--quiet"
  "piston|--cells|20|--time|1e-3|--quiet"
  "porous_screen|--cells|10|--time|1e-4|--quiet"
  "shock_tube|--cells|8|--t-end|1e-3|--quiet"
  "hanging_chain|--links|8|--length|1.2|--span|1"
  "inflated_membrane|--radius|0.5|--thickness|1e-3|--E|1e7|--nu|0.3|--pressure|100|--elements|2"
  "tumbling_box|--omega|0.1,2,0.1|--inertia|1,2,3|--t-end|0.01"
  "fluid_guide|--t-end|1e-3|--h-fine|0.5")
foreach(entry IN LISTS _ex_writers)
  string(REPLACE "|" ";" entry "${entry}")
  list(POP_FRONT entry program)
  parafsi_example_refuses(example_${program}_out_full ${program} ""
    "cannot write '/dev/full': No space left on device" ${entry} --out /dev/full)
  parafsi_example_refuses(example_${program}_out_not_a_directory ${program} ""
    "cannot open '/dev/full/x\\.csv': Not a directory" ${entry} --out /dev/full/x.csv)
endforeach()
parafsi_example_refuses(example_drop_guide_history_full drop_guide "history.csv"
  "cannot write '[^']*history\\.csv': No space left on device" --t-end 1e-3)

# ---- The two former hangs end at once, naming the flag (the library guards behind them:
# structure::relax's step limit, tests/test_structure_cable.cpp; examples::step_guard).
parafsi_example_refuses(example_hanging_chain_huge_EA hanging_chain "" "--EA: Value 1e300 not in range"
  --links 8 --length 1.2 --span 1 --EA 1e300 --out ${_ex_out}/unused_chain.csv)
parafsi_example_dir_test(example_parachute_drop_tiny_blocks_first_order parachute_drop "summary.csv|mesh.csv"
  "fabric,t_f,t_mo,t_p,F_p,v_terminal,cd_terminal,attitude_amplitude,descent_mode|t,step,blocks,cells,cells_level_0,cells_level_1"
  "1|2" "fabric,t_f,t_mo" --resolution tiny --t-end 0.02 --mesh blocks --block-size 4 --refine-every 5 --membrane-reconstruction first_order --quiet)
parafsi_example_refuses(example_bluff_body_drag_tiny_reynolds bluff_body_drag ""
  "--reynolds: Reynolds number 1e-300 is neither 0" --reynolds 1e-300 --out ${_ex_out}/unused_bluff.csv)

# ---- The command-line robustness table: every program × every numeric flag (read from
# its --help) × {nan, inf, -1, 0, 1e300, 1e-300}: a clean run or a non-zero exit naming
# the flag, each within 20 s (tests/cli/cli_robustness.py).
find_package(Python3 COMPONENTS Interpreter QUIET)
if(Python3_Interpreter_FOUND)
  add_test(NAME example_cli_robustness
    COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/tests/cli/cli_robustness.py
            --bin $<TARGET_FILE_DIR:parachute_drop> --timeout 20 --jobs 2)
  set_tests_properties(example_cli_robustness PROPERTIES TIMEOUT 900 LABELS examples)
  # scripts/descent_ensemble.py on synthetic drops with exact answers (means, standard
  # deviations, the difference's standard error, the attitude fit); skipped without numpy.
  add_test(NAME script_descent_ensemble
    COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/tests/cli/test_descent_ensemble.py
            ${PROJECT_SOURCE_DIR}/scripts/descent_ensemble.py)
  set_tests_properties(script_descent_ensemble PROPERTIES TIMEOUT 120 LABELS examples SKIP_RETURN_CODE 77)
  # scripts/opening_ensemble.py on synthetic drops with exact answers (the speed reached by
  # t_p, the opening-load coefficient, group statistics and Welch's t); standard library only.
  add_test(NAME script_opening_ensemble
    COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/tests/cli/test_opening_ensemble.py
            ${PROJECT_SOURCE_DIR}/scripts/opening_ensemble.py)
  set_tests_properties(script_opening_ensemble PROPERTIES TIMEOUT 120 LABELS examples)
endif()

# ---- The drop over MPI processes (docs/guide_mpi.md): the tiny block-mesh drop for 0.05 s
#      on one process without mpirun, then under mpiexec on N processes: history.csv,
#      summary.csv, mesh.csv and the mid-plane slice must be the same bytes. With N = 2 also a checkpoint
#      written at 0.03 s by 2 processes, restarted on 4 and on 1 (no mpirun): the same
#      history.csv again.
if(TARGET parafsi::mpi)
  set(_ex_mpi_drop ${CMAKE_CURRENT_BINARY_DIR}/run_mpi_drop.cmake)
  file(WRITE ${_ex_mpi_drop} [=[
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
set(ARGS --resolution tiny --mesh blocks --block-size 4 --refine-every 5 --quiet)  # every 5 steps: two regrids change the mesh
set(MPI ${MPIEXEC} ${NPFLAG})
function(run label)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${label} exited with ${rc}:\n${out}\n${err}")
  endif()
endfunction()
function(same a b)
  foreach(f IN LISTS ARGN)
    execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${a}/${f} ${b}/${f} RESULT_VARIABLE rc)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "${b}/${f} differs from ${a}/${f}")
    endif()
  endforeach()
  message("${b}: ${ARGN} identical to ${a}")
endfunction()
run("one process" ${PROGRAM} ${ARGS} --t-end 0.05 --vtk-every 0.025 --slice-times 0.025 --out ${OUT}/one)
run("${NP} processes" ${MPI} ${NP} ${FLAGS} ${PROGRAM} ${ARGS} --t-end 0.05 --vtk-every 0.025 --slice-times 0.025
    --out ${OUT}/np${NP})
# The slice reads the blocks the mid-plane cuts, fetched to the writing process only.
same(${OUT}/one ${OUT}/np${NP} history.csv summary.csv mesh.csv slice_00.025.csv)
# VTK: one .vtu per instant from one process; from N > 1 a .pvtu index naming N pieces, each written.
file(GLOB one_vtu ${OUT}/one/vtk/fluid_*.vtu)
list(LENGTH one_vtu n_one)
if(NOT n_one EQUAL 3)
  message(FATAL_ERROR "one process: ${n_one} fluid .vtu files, expected 3 (t = 0, 0.025, 0.05)")
endif()
if(NP GREATER 1)
  file(GLOB index ${OUT}/np${NP}/vtk/fluid_*.pvtu)
  list(LENGTH index n_index)
  if(NOT n_index EQUAL 3)
    message(FATAL_ERROR "${NP} processes: ${n_index} .pvtu files, expected 3")
  endif()
  foreach(f IN LISTS index)
    file(STRINGS ${f} listed REGEX "<Piece Source=")
    list(LENGTH listed n_listed)
    get_filename_component(stem ${f} NAME_WLE)
    get_filename_component(dir ${f} DIRECTORY)
    if(NOT n_listed EQUAL NP)
      message(FATAL_ERROR "${f} names ${n_listed} pieces, expected ${NP}")
    endif()
    math(EXPR last "${NP} - 1")
    foreach(q RANGE ${last})
      if(NOT EXISTS ${dir}/${stem}_${q}.vtu)
        message(FATAL_ERROR "${dir}/${stem}_${q}.vtu (piece ${q} of ${f}) was not written")
      endif()
    endforeach()
  endforeach()
  file(STRINGS ${OUT}/np${NP}/drop.pvd pvd_entries REGEX "pvtu")
  list(LENGTH pvd_entries n_pvd)
  if(NOT n_pvd EQUAL 3)
    message(FATAL_ERROR "drop.pvd lists ${n_pvd} .pvtu files, expected 3")
  endif()
  message("${NP} processes: 3 .pvtu indices of ${NP} pieces each, listed in drop.pvd")
endif()
if(NP EQUAL 2)
  run("checkpoint on 2" ${MPI} 2 ${FLAGS} ${PROGRAM} ${ARGS} --t-end 0.03 --checkpoint-every 0.03 --out ${OUT}/ck2)
  run("restart on 4" ${MPI} 4 ${FLAGS} ${PROGRAM} ${ARGS} --t-end 0.05 --restart ${OUT}/ck2/checkpoint.ckpt
      --out ${OUT}/rs4)
  run("restart on 1" ${PROGRAM} ${ARGS} --t-end 0.05 --restart ${OUT}/ck2/checkpoint.ckpt --out ${OUT}/rs1)
  same(${OUT}/one ${OUT}/rs4 history.csv summary.csv)
  same(${OUT}/one ${OUT}/rs1 history.csv summary.csv)
endif()
]=])
  set(_mpi_flags ${MPIEXEC_PREFLAGS})
  if(MPI_CXX_LIBRARY_VERSION_STRING MATCHES "Open MPI" OR MPIEXEC_EXECUTABLE MATCHES "openmpi|orterun")
    list(APPEND _mpi_flags --oversubscribe)
  endif()
  string(REPLACE ";" " " _mpi_flags_str "${_mpi_flags}")
  foreach(np 1 2 4)
    add_test(NAME example_parachute_drop_mpi_np${np}
      COMMAND ${CMAKE_COMMAND} -DPROGRAM=$<TARGET_FILE:parachute_drop> -DMPIEXEC=${MPIEXEC_EXECUTABLE}
              -DNPFLAG=${MPIEXEC_NUMPROC_FLAG} -DNP=${np} "-DFLAGS=${_mpi_flags}"
              -DOUT=${_ex_out}/mpi_drop_np${np} -P ${_ex_mpi_drop})
    set_tests_properties(example_parachute_drop_mpi_np${np} PROPERTIES TIMEOUT 600 LABELS "examples;mpi"
      PROCESSORS ${np}
      ENVIRONMENT "OMP_NUM_THREADS=1;OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1;OMPI_MCA_rmaps_base_oversubscribe=1")
  endforeach()
endif()
