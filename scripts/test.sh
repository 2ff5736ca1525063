#!/usr/bin/env bash
# scripts/test.sh — sets everything up (apt packages, Node test tools,
# Chromium), builds in Release and runs the whole test suite, then builds the
# library again with AddressSanitizer and UndefinedBehaviorSanitizer (clang,
# -O1, build-asan/) and runs its unit and property tests on it. CI runs
# exactly this. VOXPRESS_NO_SANITIZE=1 skips the second part (local use).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
# Elapsed time at each phase's end (CI's budget: docs/RELIABILITY.md).
phase() { echo "== $1 at $((SECONDS / 60)) min $((SECONDS % 60)) s" >&2; }
"$root/scripts/setup.sh" --tests
phase "setup and Release build done"
cd "$root/build"
ctest --output-on-failure -j "$(nproc)"
phase "Release suite done"
[ "${VOXPRESS_NO_SANITIZE:-0}" = 1 ] && exit 0

echo "== the unit and property tests under ASan + UBSan" >&2
suites=(core_tests extract_tests io_tests eval_tests smooth_tests simplify_tests voxart_tests render_tests labels_tests chunk_tests)
# clang when present (setup installs it): it compiles the sanitized library
# in half gcc's time.
compilers=(); command -v clang++ >/dev/null 2>&1 && compilers=(-DCMAKE_CXX_COMPILER=clang++ -DCMAKE_C_COMPILER=clang)
cmake -S "$root" -B "$root/build-asan" -G Ninja "${compilers[@]}" -DCMAKE_BUILD_TYPE=Sanitize -DCMAKE_CXX_FLAGS_SANITIZE="-O1 -g0" \
  -DCMAKE_C_FLAGS_SANITIZE="-O1 -g0" -DVOXPRESS_SANITIZE=ON -DVOXPRESS_PYTHON=OFF -DVOXPRESS_BUILD_BENCH=OFF >/dev/null
cmake --build "$root/build-asan" -j "$(nproc)" --target "${suites[@]}" >&2
phase "sanitized build done"
# Each suite's executable directly (the CLI, Python and browser tests ran in
# Release above), two at a time; any sanitizer report fails the suite. Left
# out (all passed in Release above): the fidelity checks at 64-128^3 (10-160 s
# each under ASan), which run the very code the property corpus runs, on
# bigger volumes; the 1-vs-N-thread comparisons (the sanitizers check memory,
# not races, and every other test runs on all cores too); the flats' property
# corpus (the sharpening's corpus runs press_with_flats on the same volumes);
# the conversion of the shared voxel art (its parsing is checked by
# Voxart.SharedFilesHaveTheDocumentedContents); the crossing plates and the
# generated shapes at random rotations (the property corpus holds both
# kinds, smaller); the metric, truth and option-effect checks on 64-128^3
# volumes (their code runs in the suites kept, on smaller inputs); the
# voxelizer at random rotations and the shared medical volumes' documented
# facts (their code runs in the other Voxelize and VolumeIO tests and the
# fuzzers); the filleted solids' decisions at 48-64^3 (39-85 s each under
# ASan; their rules run in Flats.CreaseFitKeepsOffFillets, kept: a filleted
# cylinder through the whole layer) and the invariance
# checks (74 s, and 70 s for the default pipeline's and the moved origin's:
# bitwise equality of t and meshes, whose code the corpora run under the
# sanitizers). The corpus itself is smaller under the sanitizers
# (tests/test_util.cpp), and the pressing corpus runs one circle correction.
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export GTEST_FILTER="-Sharpen.CadPartErrorDropsAndItsCreasesAreFound:Sharpen.RotatedBoxesGetTheirEdgesBack:\
Sharpen.SharpAngleOptionControlsTheLabels:Sharpen.ThinPlatesGetBothEdgesOfTheirRim:\
Flats.RotatedBoxesHaveExactlySixFlatsWithinOneDegree:Flats.CadPartPlanarFacesFoundNoneSpurious:\
Flats.CadPartAt256FoundNoneSpurious:Flats.RotatedCylinderHasTwoCapsAndACurvedWall:\
Flats.RotatedBoxesAt64AlmostAlwaysHaveExactlySixFlats:Flats.OrganicShapesHaveNoFlats:\
Flats.FlatsMakeTheBoxMoreAccurate:Flats.FilletTangentToAFlatIsNotAJunction:\
Sharpen.JoinedVerticesTakeTheNearestPlane:Sharpen.FandiskGetsMoreAccurate:\
Pressing.MeetsTheFidelityTargetsOnSphereAndTorus:Pressing.QuadricFitBringsTightCurvesCloserToTheTruth:\
Metrics.MidpointRowOfThePaperIsReproduced:Shapes.CadPartMeshIsAValidSolidMatchingItsClosedFormVolume:\
Written.RotatedRealMeshKeepsTheGuaranteeInEveryFormat:\
Written.AnisotropicPartFarFromTheOriginKeepsTheGuaranteeInEveryFormat:Passes.EachPassOffKeepsTheGuarantees:\
Flats.FandiskPlanarFacesFoundAndStagesBeatTheMidpoint:Flats.PropertyCorpusKeepsEveryGuarantee:\
Pipeline.SameMeshForOneAndManyThreadsOnThePropertyVolumes:Sharpen.SameResultForOneAndManyThreads:\
Flats.SameResultForOneAndManyThreads:Voxart.SharedVoxelArtLoadsAndConverts:\
Sharpen.CrossingThinPlatesKeepEveryGuarantee:Pressing.GeneratedShapesAtRandomRotationsStayValid:\
Metrics.ScaledSphereHasTheAnalyticDistanceAndVolume:Metrics.QuadratureRmsAgreesWithTheSamplesAndIgnoresTheirSeed:\
Metrics.MidpointRowOnFandisk:Metrics.RotatedBoxMatchesQuadrature:Metrics.TranslatedBoxMatchesQuadrature:\
Truth.SharpEdges:Shapes.SampledVolumeMatchesAnalyticVolume:Flats.JunctionAngleOptionControlsJunctions:\
Sharpen.CurvedCreasesOnlyWhereTheyContinueAFlatsCrease:Pressing.ArcLengthResamplingBeatsThePlainBilaplacian:\
Pipeline.PressingStagesAndOverridesAreHonoured:Flats.WithoutFlatsTheResultIsThePlainPress:\
Pressing.AnisotropicSpacingWorksInPhysicalSpace:Voxelize.ExactAgainstTheModelAtRandomRotations:\
VolumeIO.SharedMedicalVolumesMatchTheirDocumentedFacts:Sharpen.FilletsTheLatticeResolvesStayRound:\
Invariance.RealMaskShiftedPaddedAndCroppedGivesTheSameT:Invariance.ShiftedAndPaddedRotatedSphereGivesTheSameT:\
Invariance.DefaultPipelineOnShiftedPaddedAndCroppedVolumes:Invariance.MovedOriginGivesTheSameT:\
Simplify.SameBytesForAnyThreadCount:Flats.FilletsTheLatticeResolvesAreNotFlattened:\
Flats.FilletsBesideOneFlatAreNotFlattened:Flats.SharpEdgesEndingAtAFilletStayJunctions:\
Sharpen.StripsOfResolvedFilletsStayCurved"
# The label maps' tests run the cases small enough for the sanitizers (each
# stage of the shared surface: cases, extraction, press, fit, flats and
# sharpening through press_shared_labels on the phantom, simplification);
# the 3-label pattern sweep, the adversarial volumes, the assemblies and the
# 61-label map (40-250 s each under ASan) ran in Release above.
export LABELS_FILTER="Labels.TableMatchesABruteForceCount:Labels.MaskOnTheBoxIsTheLabelEverywhere:\
Labels.PhantomEveryLabelKeepsItsSamplesInsideAndTheOthersOut:Labels.LayeredSegmentationEverySegmentOnItsLayer:\
Labels.BadInputIsRefusedNamingTheFile:LabelCases.TwoLabelsAreTheBinaryCaseWithTheLargerLabelInside:\
LabelCases.PatternsOfFourToEightLabelsCloseUpOrAreRefused:LabelCases.PatternsRankLabelsByValue:\
SharedSurface.PhantomLabelsAreClosedAndShareTheirInterfaces:SharedSurface.OneLabelIsTheBinaryMidpointSurface:\
SharedSurface.SameBytesForAnyThreadCountAndBadInputIsRefused:SharedPress.PressedPhantomKeepsEveryGuarantee:\
SharedPress.ShiftedPaddedAndCroppedPhantomGivesTheSameSurface:SharedFit.NestedSphereGetsItsBinaryFit:\
SharedSimplify.PhantomKeepsEveryGuarantee"
# The chunked run's rounds under the sanitizers on one small case (the
# others, 7-10 s each in Release, ran above).
export CHUNK_FILTER="Chunked.SameBytesForAnyThreadCountAndPieceOrder:Chunked.AHaloNarrowerThanOneSweepIsRefused:\
Chunked.OneBlockIsTheWholeRunBitForBit:Chunked.GridCoversTheVolumeOnce"
# smooth_tests, the longest, runs as four shards; the longest runs start
# first (eval, io and extract next), so the two slots end together.
runs=(smooth_tests:0:4 smooth_tests:1:4 smooth_tests:2:4 smooth_tests:3:4 eval_tests:0:1 labels_tests:0:1 io_tests:0:1
      extract_tests:0:1 simplify_tests:0:1 voxart_tests:0:1 core_tests:0:1 render_tests:0:1 chunk_tests:0:1)
printf '%s\n' "${runs[@]}" | xargs -P "$(nproc)" -I{} sh -c '
  run=$1; t=${run%%:*}; rest=${run#*:}; i=${rest%%:*}; n=${rest#*:}
  log="$0/build-asan/$t.$i.log"
  [ "$t" = labels_tests ] && export GTEST_FILTER="$LABELS_FILTER"
  [ "$t" = chunk_tests ] && export GTEST_FILTER="$CHUNK_FILTER"
  GTEST_SHARD_INDEX=$i GTEST_TOTAL_SHARDS=$n "$0/build-asan/tests/$t" --gtest_brief=1 > "$log" 2>&1 &&
    echo "sanitized $t ($((i + 1))/$n): passed" ||
    { echo "sanitized $t ($((i + 1))/$n): FAILED"; tail -40 "$log"; exit 1; }' "$root" {}
phase "sanitized suites done"
