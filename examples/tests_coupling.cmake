# Smoke tests of the coupling example programs (included from examples/CMakeLists.txt
# when tests are on): piston, porous_screen and leak_box run briefly with each coupling
# they accept, print their key=value result, write a CSV with the exact header and at
# least one data row; bad flags fail. Total run time: a few seconds.

set(_cpl_out ${CMAKE_CURRENT_BINARY_DIR}/test_output_coupling)
file(MAKE_DIRECTORY ${_cpl_out})

# Helper script: run PROGRAM ARGS (| separated) [--out OUT], require exit code 0, the
# output to match EXPECT and, when HEADER is set, OUT's first line to equal HEADER
# with at least one data row.
set(_cpl_check ${CMAKE_CURRENT_BINARY_DIR}/run_coupling_example.cmake)
file(WRITE ${_cpl_check} [=[
string(REPLACE "|" ";" ARGS "${ARGS}")
if(DEFINED OUT)
  file(REMOVE ${OUT})
  list(APPEND ARGS --out ${OUT})
endif()
execute_process(COMMAND ${PROGRAM} ${ARGS} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("${out}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${PROGRAM} exited with ${rc}:\n${err}")
endif()
if(NOT out MATCHES "${EXPECT}")
  message(FATAL_ERROR "output does not match '${EXPECT}'")
endif()
if(DEFINED HEADER AND NOT HEADER STREQUAL "")
  file(STRINGS ${OUT} lines)
  list(LENGTH lines n)
  list(GET lines 0 first)
  if(NOT first STREQUAL HEADER)
    message(FATAL_ERROR "${OUT}: header '${first}', expected '${HEADER}'")
  endif()
  if(n LESS 2)
    message(FATAL_ERROR "${OUT}: no data rows")
  endif()
endif()
]=])

# parafsi_coupling_example(NAME PROGRAM HEADER EXPECT args...); HEADER "" = no --out.
function(parafsi_coupling_example name program header expect)
  list(JOIN ARGN "|" _args)
  set(_out "")
  if(NOT header STREQUAL "")
    set(_out -DOUT=${_cpl_out}/${name}.csv)
  endif()
  add_test(NAME ${name}
    COMMAND ${CMAKE_COMMAND} -DPROGRAM=$<TARGET_FILE:${program}> "-DARGS=${_args}" ${_out} "-DHEADER=${header}"
            "-DEXPECT=${expect}" -P ${_cpl_check})
  set_tests_properties(${name} PROPERTIES TIMEOUT 120 LABELS "examples;coupling" ENVIRONMENT "OMP_NUM_THREADS=1")
endfunction()

function(parafsi_coupling_example_fails name program)
  add_test(NAME ${name} COMMAND ${program} ${ARGN})
  set_tests_properties(${name} PROPERTIES WILL_FAIL TRUE TIMEOUT 60 LABELS "examples;coupling")
endfunction()

# ---- piston, both couplings: short run on the default duct.
if(TARGET piston)
  parafsi_coupling_example(example_coupling_piston piston "" "pressure_rise=.*rho_c_v=" --time 0.002)
  parafsi_coupling_example(example_coupling_piston_embedded piston "" "pressure_rise=.*rho_c_v=" --time 0.002
                           --coupling embedded)
  parafsi_coupling_example_fails(example_coupling_piston_bad_coupling piston --coupling glue)
  parafsi_coupling_example_fails(example_coupling_piston_bad_velocity piston --velocity -1)
endif()

# ---- porous_screen and leak_box with both couplings (coarse, short).
foreach(c IN ITEMS penalty embedded)
  parafsi_coupling_example(example_coupling_porous_screen_${c} porous_screen "t,pressure_drop,through_velocity"
    "pressure_drop=[0-9.e+-]+ through_velocity=" --coupling ${c} --fabric mat509 --velocity 1 --cells 20 --time 0.01
    --quiet)
  parafsi_coupling_example(example_coupling_leak_box_${c} leak_box "t,pressure_left,pressure_right,leak_velocity"
    "leak_velocity=" --coupling ${c} --pressure-jump 50 --cells 20 --time 0.005 --quiet)
endforeach()
parafsi_coupling_example(example_coupling_porous_screen_inclined_face porous_screen "t,pressure_drop,through_velocity"
  "pressure_drop=[0-9.e+-]+ through_velocity=" --coupling embedded --through-flow face --incline 30 --fabric mat509
  --velocity 1 --cells 20 --time 0.005 --quiet)
parafsi_coupling_example_fails(example_coupling_porous_screen_bad_through_flow porous_screen --through-flow normal
  --out ${_cpl_out}/unused.csv)
parafsi_coupling_example(example_coupling_leak_box_embedded_zero leak_box "t,pressure_left,pressure_right,leak_velocity"
  "leak_velocity=0 " --coupling embedded --pressure-jump 50 --cells 20 --time 0.005 --quiet)
parafsi_coupling_example_fails(example_coupling_porous_screen_bad_coupling porous_screen --coupling foo
  --out ${_cpl_out}/unused.csv)
parafsi_coupling_example_fails(example_coupling_porous_screen_bad_fabric porous_screen --fabric silk
  --out ${_cpl_out}/unused.csv)
parafsi_coupling_example_fails(example_coupling_leak_box_bad_jump leak_box --pressure-jump -5
  --out ${_cpl_out}/unused.csv)

# ---- bluff_body_drag (when built).
if(TARGET bluff_body_drag)
  foreach(shape IN ITEMS disk cup)
    parafsi_coupling_example(example_coupling_bluff_${shape} bluff_body_drag "t,drag_coefficient,side_force_y,side_force_z,probe_v,probe_w"
      "drag_coefficient=[0-9.e+-]+ " --shape ${shape} --coupling embedded --cells 4 --time 0.002 --quiet)
  endforeach()
  parafsi_coupling_example(example_coupling_bluff_disk_penalty bluff_body_drag "t,drag_coefficient,side_force_y,side_force_z,probe_v,probe_w"
    "drag_coefficient=[0-9.e+-]+ " --shape disk --coupling penalty --cells 4 --time 0.002 --quiet)
  # The wake closures and the symmetry kick: the wake probe's spectrum is printed.
  foreach(closure IN ITEMS mixing_length smagorinsky)
    parafsi_coupling_example(example_coupling_bluff_disk_${closure} bluff_body_drag
      "t,drag_coefficient,side_force_y,side_force_z,probe_v,probe_w"
      "drag_coefficient=[0-9.e+-]+ .* strouhal=[a-z0-9.e+-]+ probe_amplitude=[0-9.e+-]+ shedding_periods=[0-9.e+-]+ closure=${closure} reynolds=5.27"
      --shape disk --cells 4 --time 0.03 --kick 0.05 --closure ${closure} --quiet)
  endforeach()
  parafsi_coupling_example_fails(example_coupling_bluff_bad_closure bluff_body_drag --closure k_epsilon
    --out ${_cpl_out}/unused.csv)
  parafsi_coupling_example_fails(example_coupling_bluff_bad_shape bluff_body_drag --shape sphere
    --out ${_cpl_out}/unused.csv)
  parafsi_coupling_example_fails(example_coupling_bluff_bad_coupling bluff_body_drag --coupling foo
    --out ${_cpl_out}/unused.csv)
  # The grid's box and core: a larger box runs; a probe in the sponge, a sliver cell and a
  # huge grid are refused.
  parafsi_coupling_example(example_coupling_bluff_disk_box bluff_body_drag "t,drag_coefficient,side_force_y,side_force_z,probe_v,probe_w"
    "drag_coefficient=[0-9.e+-]+ " --shape disk --cells 4 --time 0.002 --core-length 3 --core-width 1 --domain-length 8
    --domain-width 3 --stretch 1.2 --quiet)
  # The inflow further upstream, no sponge, one-sided cells beside the body: the stream's total
  # pressure ahead and the reconstruction are printed.
  parafsi_coupling_example(example_coupling_bluff_disk_upstream bluff_body_drag "t,drag_coefficient,side_force_y,side_force_z,probe_v,probe_w"
    "drag_coefficient=[0-9.e+-]+ .* upstream_total_cp=[0-9.e+-]+ .* membrane_reconstruction=one_sided" --shape disk
    --cells 4 --time 0.002 --domain-upstream 6 --no-sponge --membrane-reconstruction one_sided --quiet)
  parafsi_coupling_example(example_coupling_bluff_disk_blocks_upstream bluff_body_drag
    "t,drag_coefficient,side_force_y,side_force_z,probe_v,probe_w" "drag_coefficient=[0-9.e+-]+ .* upstream_total_cp="
    --shape disk --mesh blocks --cells 8 --time 0.0005 --domain-upstream 6 --quiet)
  parafsi_coupling_example_fails(example_coupling_bluff_upstream_too_short bluff_body_drag --domain-upstream 0.5
    --out ${_cpl_out}/unused.csv)
  parafsi_example_refuses(example_coupling_bluff_sponge_upstream bluff_body_drag ""
    "the far-field sponge .* reaches the air just upstream of the body" --cells 4 --domain-upstream 1
    --out ${_cpl_out}/unused.csv)
  parafsi_example_refuses(example_coupling_bluff_sponge_rim bluff_body_drag ""
    "the far-field sponge reaches the body's rim" --cells 8 --domain-width 1 --core-width 0.6
    --out ${_cpl_out}/unused.csv)
  parafsi_example_refuses(example_coupling_bluff_one_sided_penalty bluff_body_drag ""
    "--membrane-reconstruction one_sided needs --coupling embedded" --coupling penalty
    --membrane-reconstruction one_sided --out ${_cpl_out}/unused.csv)
  # The block mesh (the finest level on the core, 2:1 rings outside), with a closure's wall distance on blocks.
  parafsi_coupling_example(example_coupling_bluff_disk_blocks bluff_body_drag "t,drag_coefficient,side_force_y,side_force_z,probe_v,probe_w"
    "drag_coefficient=[0-9.e+-]+ .* blocked_area_ratio=1.03451 " --shape disk --mesh blocks --cells 8 --time 0.0005 --quiet)
  # The staircase disk at 8 cells per diameter on the tensor grid (a face line on the axis): 52 face
  # centres (i + 1/2, j + 1/2) h inside radius 4 h, 52 / 16π = 1.03451 of the disk's area.
  parafsi_coupling_example(example_coupling_bluff_disk_blocked_area bluff_body_drag
    "t,drag_coefficient,side_force_y,side_force_z,probe_v,probe_w" "blocked_area_ratio=1.03451 "
    --shape disk --cells 8 --time 0.0002 --quiet)
  # At 5 cells per diameter the core (±0.75 D) holds 8 cells of 0.0375 m, not D/5: 24 faces of
  # that width, 24 · 0.0375² / (π 0.1²) = 1.0743 (the area of the faces, not a count times h²).
  parafsi_coupling_example(example_coupling_bluff_disk_blocked_area_narrow_cells bluff_body_drag
    "t,drag_coefficient,side_force_y,side_force_z,probe_v,probe_w" "blocked_area_ratio=1.0743 "
    --shape disk --cells 5 --time 0.0002 --quiet)
  parafsi_coupling_example(example_coupling_bluff_cup_blocks_mixing_length bluff_body_drag
    "t,drag_coefficient,side_force_y,side_force_z,probe_v,probe_w"
    "drag_coefficient=[0-9.e+-]+ .* closure=mixing_length" --shape cup --mesh blocks --block-size 4 --cells 8 --time 0.0005
    --closure mixing_length --quiet)
  # The scheme's dissipation: HLLC without the low-Mach fix and the minmod limiter (inviscid only).
  parafsi_coupling_example(example_coupling_bluff_disk_hllc_minmod bluff_body_drag
    "t,drag_coefficient,side_force_y,side_force_z,probe_v,probe_w" "drag_coefficient=[0-9.e+-]+ .* flux=hllc limiter=minmod"
    --shape disk --cells 4 --time 0.002 --flux hllc --limiter minmod --quiet)
  parafsi_example_refuses(example_coupling_bluff_minmod_viscous bluff_body_drag ""
    "--flux and --limiter other than hllc_lm and van_leer need inviscid air" --limiter minmod --closure smagorinsky
    --out ${_cpl_out}/unused.csv)
  parafsi_example_refuses(example_coupling_bluff_blocks_sponge_on_body bluff_body_drag ""
    "the far-field sponge reaches the body's rim" --mesh blocks --domain-width 1 --out ${_cpl_out}/unused.csv)
  parafsi_coupling_example_fails(example_coupling_bluff_probe_in_sponge bluff_body_drag --domain-length 2.5
    --out ${_cpl_out}/unused.csv)
  parafsi_coupling_example_fails(example_coupling_bluff_sliver_cell bluff_body_drag --core-width 2.49
    --out ${_cpl_out}/unused.csv)
  parafsi_coupling_example_fails(example_coupling_bluff_huge_grid bluff_body_drag --stretch 1 --domain-length 200
    --domain-width 100 --out ${_cpl_out}/unused.csv)
endif()
