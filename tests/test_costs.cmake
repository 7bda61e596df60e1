# Start order of the slow tests (included by CTest after the discovered tests;
# tests/CMakeLists.txt). In a clean clone CTest has no cost data
# (Testing/Temporary/CTestCostData.txt) and starts the tests in their registration order, so a
# slow test registered late can run alone at the end while the other core idles. COST makes the
# slow ones start first. The values are seconds under ASan + UBSan (wall, ctest -j2 at load ~4;
# docs/build.md, 2026-11-30); the last entries, Release-only tests, are 5x their Release
# seconds (about the sanitizer factor). Only the order matters. A name that is not registered in
# a build (a [verification] test in the sanitizer build) is ignored; a renamed test just loses
# its place (CTest's own cost data take over after one run).
set(knit_test_costs
  "test_meso:energy fit: recovers the synthetic hyperelastic law within 3 % of the range=26.68"
  "test_common:energy law: polar-grid checks at every loop length and midway=24.20"
  "test_meso:knit-meso: every command refuses an output it cannot write before any work=22.09"
  "test_macro:fuzz: mutated case files load or throw InputError=17.10"
  "test_meso:uniaxial path: the lateral stress vanishes at every converged step=14.21"
  "test_meso:knit-meso cell/path: every option is checked for finiteness and range first=12.96"
  "test_meso:energy fit: the uniaxial-stress diagnostic compares the law driven like the cell=9.78"
  "test_meso:rod case: a reversed end moment stops at the work cap, outputs of converged steps kept=8.94"
  "test_meso:knit-meso sweep: a sweep that writes nothing says so and leaves no new directories=8"
  "test_meso:4.5 mm cell is stiffer than 6.5 mm in both directions=7.86"
  "test_common:fuzz: mutated database files load or throw InputError=7.66"
  "test_meso:knit-meso path: a killed run leaves the previous output as it was=7.37"
  "test_meso:knit-meso path --uniaxial: the lateral stress vanishes at every step=6.78"
  "test_meso:knit-meso cell --config reads the cell parameter file=6.69"
  "test_meso:sweep cell runner: uniaxial and gradient paths record F, E, S consistently=6.68"
  "test_meso:fit: robust loss and foot-point optimization run and stay accurate=6.44"
  "test_meso:knit-meso: an output in use by another run is refused, naming its pid=6.40"
  "test_meso:cell Jacobian (rod + periodic rows + frictional contact) matches finite differences=6.27"
  "test_macro:design file: bad input is a JSON-pointer error and exit 2=5.97"
  "test_common:paper law extension: polar grid, S continuous (Lipschitz), C = FD of S=5.90"
  "test_meso:knit-meso synth --no-fit, then fit, refits from the raw data=5.71"
  "test_macro:a refinement that cannot fit in memory is refused at load with the estimate=5.42"
  "test_meso:mirror-symmetric shear paths give mirror-symmetric stresses=5.15"
  "test_meso:reduced sweep on the unit cell: cell -> fit -> database the macroscale reads=28"
  "test_meso:energy fit: the network family recovers the synthetic law=20"
  "test_meso:knit-meso sweep: killed midway then resumed recomputes nothing and equals an uninterrupted run=17"
  "test_macro:reduced sweep database drives a knit-macro tensile case=16"
  "test_meso:knit-meso sweep: mpirun with 2 ranks gives the serial database=14")
foreach(entry IN LISTS knit_test_costs)
  string(REGEX MATCH "^(.*)=([0-9.]+)$" _ "${entry}")
  set_tests_properties("${CMAKE_MATCH_1}" PROPERTIES COST ${CMAKE_MATCH_2})
endforeach()
