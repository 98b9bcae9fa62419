#!/usr/bin/env bash
# Sanitizer build and the fast unit tests under AddressSanitizer + UndefinedBehaviorSanitizer.
#
# Configures build-asan/ (Debug at -O1 with line tables and _GLIBCXX_ASSERTIONS, MLC_SANITIZE=ON),
# builds the unit tests and runs the fast ones there (`ctest -LE "^(slow|cli)$"`, without the five
# whole-run tests named below); prints one summary line, or ctest's output on failure.
# With clang (the default when present) the same build also has MLC_BUILD_FUZZ=ON, so that
# scripts/fuzz.sh reuses its libraries instead of compiling the tree a third time.
#
# hypre/MPI are left out (MLC_WITH_HYPRE=OFF): the Debian OpenMPI and hypre libraries are not
# instrumented, and MPI_Init + MPI_Finalize alone make LeakSanitizer report 32 leaked
# allocations inside OpenMPI 4.1 and fail the process, which would bury our own reports (a
# suppression file would have to follow OpenMPI's internals). The BoomerAMG tests therefore run
# only in the normal build. The benchmarks are left out too.
#
# The Python module is left out (MLC_BUILD_PYTHON=OFF), and with it the Python tests: an
# instrumented extension can only be loaded into the uninstrumented /usr/bin/python3 with the ASan
# runtime preloaded, and then LeakSanitizer reports CPython's own allocations at exit. What the
# module adds (bindings, no numerics) is tested in the normal build; the library code it calls is
# what runs here. The package test (install + external build) needs the driver and is left out
# too (it is registered only without MLC_SANITIZE).
#
# Environment: MLC_SANITIZE_CXX picks the compiler (default clang++-14 or clang++ if present, else g++);
# MLC_JOBS the build parallelism (default: number of cores, at most 2).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/deps.sh > /dev/null
dir=build-asan
if [ -n "${MLC_SANITIZE_CXX:-}" ]; then
  cxx=$MLC_SANITIZE_CXX
elif command -v clang++-14 > /dev/null; then
  cxx=clang++-14
elif command -v clang++ > /dev/null; then
  cxx=clang++
else
  cxx=g++
fi
fuzz=OFF
"$cxx" --version 2>/dev/null | grep -q clang && fuzz=ON
jobs=${MLC_JOBS:-$(nproc 2>/dev/null || echo 2)}
[ "$jobs" -gt 2 ] && jobs=2
mkdir -p "$dir"
log=$dir/build.log
start=$(date +%s)
# -O1: Debug at -O0 makes the Eigen kernels several times slower under ASan. The test files and
# the run/studies/bench libraries, which drive those kernels, are compiled at -O0 with ASan alone
# (mlc_sanitize_lightly in CMakeLists.txt): a third of their -O1 compile time.
# Ninja where present, as in scripts/build.sh (here it saves about a quarter of the build time).
gen=()
[ ! -f "$dir/CMakeCache.txt" ] && command -v ninja > /dev/null && gen=(-G Ninja)
cmake -S . -B "$dir" "${gen[@]}" -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_BUILD_TYPE=Debug \
  "-DCMAKE_CXX_FLAGS_DEBUG=-O1 -g1 -D_GLIBCXX_ASSERTIONS" -DCGAL_DO_NOT_WARN_ABOUT_CMAKE_BUILD_TYPE=TRUE \
  -DMLC_SANITIZE=ON -DMLC_WITH_HYPRE=OFF -DMLC_BUILD_BENCH=OFF -DMLC_BUILD_TESTS=ON -DMLC_BUILD_PYTHON=OFF \
  -DMLC_BUILD_FUZZ="$fuzz" > "$log" 2>&1 || { cat "$log"; exit 1; }
# Only the unit-test executables (and the fuzz targets): not the driver, whose end-to-end tests
# (label cli) are left out below, as they run the time-bounded studies 5 to 10 times slower.
targets=$(cmake --build "$dir" --target help | grep -oE "\b(test|fuzz)_[a-z_]+\b" | grep -v "^test_common" | sort -u)
cmake --build "$dir" -j"$jobs" --target $targets >> "$log" 2>&1 || { tail -n 60 "$log"; exit 1; }
built=$(date +%s)
# halt_on_error: the first report fails the test (UBSan is already -fno-sanitize-recover).
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:halt_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
out=$dir/ctest.log
# Whole-run tests that take over 10 s under the sanitizers are left to the Release suite: every
# new scene coarse-to-fine, the multilevel rows of error-vs-time, Mindlin's partial slip, the
# aggregation-mg runs on the exported square, the level-3 size predictions, the level-independence
# of the V-cycle, BiCGStab over the threads, the coarse-to-fine square and increment transfer, the
# damped two-body default on the dovetail, the lattice transfer products, the lattice and
# single-precision multigrids against their references, the recovered levels, the held corner and
# the held Hertz half model, the coarse/fine variants of the Krylov system, mg inside each Krylov
# method and its exact fallback, the dovetail on levels 0-2, the 3D manufactured solution over
# levels 0-3, hertz3d on level 2 against Hertz, block3d's multigrid and cold runs on level 2 and
# stack3d's two-body runs on levels 0-2 (their search and weights have their own unit tests, and
# stack3d's level 0 runs here in TwoBody3.Stack3dNodalWeightsMissThePatchTestOnNonMatchingMeshes),
# shear3d, the 3D error-vs-time rows, the 3D extremes, the 3D elastic multigrid over box3d's and
# the two-volume mesh's levels, Mindlin's first-step traction over three contact widths, and nine
# that take 10 to 22 s under ASan: three aggregation-mg checks on the square (smoothed prolongation,
# Galerkin product and its refresh), the 3D size predictions, the released axis, the attached
# Hertz sphere, every preconditioner on the fine system, the 3D secant predictor and the inexact
# Newton forcing terms; and ILU(0), SORCF and MGR on block3d's level 1 (CF's solve of it runs here).
# What they run is covered here by the unit tests of the same code (levels, solvers, contact,
# smoothers, transfer, the hierarchy tests); this keeps .ci/run well under 40 minutes
# (docs/testing.md#testing-hostile).
heavy="^(NewScenes\.CoarseToFineNewtonAndMgSolveEveryNewScene|ErrorVsTime\.MultilevelRowsConvergeAndTheirErrorFallsWithTheLevel|Mindlin\.PartialSlipStickZoneMatchesCattaneoMindlin|AlgebraicMultigrid\.SolvesTheSquareExportedFromLevel2LikeSchur|PredictLevelSizes\.RefinementCountsAreExactAndUnknownsClose"
heavy+="|Multigrid\.VCycleIsLevelIndependentAsCGPreconditioner|Krylov\.BicgstabOverTheThreadsIsTheWholeVectorIterationBitForBit|CoarseToFine\.SquareMatchesColdStartWithHalfTheNewtonIterations|MultilevelPreconditioner\.TheDampedTwoBodyDefaultSolvesTheDovetail"
heavy+="|LatticeTransfer\.TAndRThroughTheLatticeAreTheirCsrProductsBitForBit|LatticeMultigrid\.SquareLevel4LikeTheBlockSmoother|SinglePrecisionMultigrid\.SquareLevel3LikeDouble|CoarseToFine\.IncrementTransferGivesTheSameSolutionAndPredictsAtLeastAsWell"
heavy+="|RecoveredLevels\.TheExportedSquareSolvesAsTheRefinedSquareDoes|HeldSupports\.SquareWithItsContactCornerHeldInUxSolvesAlikeByEverySolver"
heavy+="|KrylovSystem\.CoarseFineVariantsSolveTheFineSystem|MultilevelPreconditioner\.WorksInsideCgsBicgstabAndGmres|MultilevelPreconditioner\.TheExactFallbackSolvesWhatTheMultigridCannot"
heavy+="|HeldSupports\.FrictionalHertzHalfModelCarriesTheLoadAndSolvesAlikeByEverySolver|Dovetail\.EquilibriumMirrorSymmetryAndCoulombOnLevels0To2"
heavy+="|Elastic3dConvergence\.ManufacturedSolutionOrderOneInEnergyTwoInL2"
heavy+="|Accuracy3\.Hertz3dLevel2AgainstHertz|Contact3\.Block3dMultigridIterationsAndCoarseToFineAgainstCold"
heavy+="|TwoBody3\.Stack3dPatchTestExactWithSegmentAndDualWeightsOnLevels0To2|TwoBody3\.Stack3dColdMultigridSolvesTheTwoBodyNewtonSystems"
heavy+="|TwoBody3\.Shear3dBalancesItsLoadsAndItsSlipZoneGrowsWithThePush|ErrorVsTime3\.ReferenceRowIsExactAgainstItselfAndErrorsFallWithTheLevel"
heavy+="|ErrorVsTime3\.ErrorsAgainstAFinerReferenceFallWithTheLevel|Extremes3\.EveryCaseConvergesOrIsDiagnosedWithFiniteNumbers"
heavy+="|Elastic3dMg\.BoxScene_IterationsBoundedOverLevelsAndSolutionIsTheDirectOne|Elastic3dMg\.GmshTwoVolumes_BodiesMaterialsAndIterationsBoundedOverLevels"
heavy+="|Mindlin\.StepOneTractionIsAFiniteGeometryEffectThatShrinksWithTheContactWidth"
heavy+="|Aggregation\.SmoothedProlongationReproducesRigidModesAwayFromTheSupports|Aggregation\.CoarseStiffnessIsTheGalerkinProductComputedDensely"
heavy+="|Aggregation\.GalerkinRefreshOfChangedRowsIsTheFullProduct|Elastic3dLevels\.PredictedSizesAgainstTheBuiltLevels"
heavy+="|AxisRelease\.AxisHeldThenReleasedWithBalanceAndCoulomb|Contact3Scenes\.Hertz3dSphereIsAttachedAndRefinementPutsItsVerticesOnIt"
heavy+="|KrylovSystem\.EveryPreconditionerSolvesTheFineSystem|Contact3\.SecantPredictorExactUnderProportionalLoading"
heavy+="|InexactNewton\.ForcingTermsSaveKrylovIterationsAndGiveTheSameSolution"
heavy+="|KrylovSystem3\.EveryOtherPreconditionerOfThe3dFamilyGivesTheMultigridSolution)$"
if ctest --test-dir "$dir" -LE "^(slow|cli)$" -E "$heavy" -j"$jobs" --output-on-failure > "$out" 2>&1; then
  n=$(grep -oE "out of [0-9]+" "$out" | tail -n 1 | grep -oE "[0-9]+")
  echo "sanitize: ${n:-?} tests passed under address+undefined ($cxx, build-asan;" \
    "build $((built - start)) s, tests $(($(date +%s) - built)) s)"
else
  cat "$out"
  echo "sanitize: FAILED under address+undefined sanitizers (log in $out)"
  exit 1
fi
