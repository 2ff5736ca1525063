// Private to the feature layer: its internal constants, each with the reason
// for its value (the public options are FlatOptions / SharpenOptions; the
// passes are switched in voxpress/features/passes.h).
#pragma once

namespace voxpress::detail {

// --- flats (Section 3)
constexpr double kFlatCone = 3;          // degrees: a vertex votes for directions this close to its normal (the estimate's spread on a face)
constexpr double kFlatTolerance = 0.3;   // cells: core vertices lie this close to the plane (the estimate's error on a face)
constexpr double kFlatMaxBend = 5;       // degrees: largest normal trend across a core (a gently curved face's strip bends more)
constexpr double kFlatMaxSpread = 1.4;   // degrees: largest median normal deviation in a core (the estimate's own noise on a face)
constexpr double kFlatWidthShare = 0.3;  // a flat is at least this share of sqrt(min_area) wide (no strips along a curved face)
constexpr double kFlatMaxWidth = 3;      // cells: ... and need not be wider than this
constexpr int kRimRings = 2;             // surface rings a flat takes around its core (the estimate rounds a face's last two rings)
constexpr double kRimTangentAngle = 15;  // degrees: a curved side continuing the flat this closely is a fillet (rim-tangent)
constexpr double kMergeAngle = 4;        // degrees: adjacent flats this close are merged when one plane stabs both
constexpr double kCurvedGain = 1.3;      // a quadric stabbing this many times as many sticks as the plane refuses the flat
constexpr int kEstimateIterations = 100; // Pressing iterations of each estimate (the estimate's normals settle by then)
constexpr int kSecondEstimateIterations = 50;  // the second estimate (flats frozen); 30 lost sharp precision on a 4-cell plate (BENCHMARKS, The flats' estimates)
constexpr int kDetectionPasses = 2;      // the second re-estimates with the first's flats frozen (faces beside rounded edges)
// --- junctions (Section 3)
constexpr double kTangentResidual = 0.1;       // cells RMS: a curved side fitting a quadric this well may be tangent (tangent-borders)
constexpr double kJunctionRingOffPlane = 0.1;  // cells: fresh vertices this close to the flat's plane leave the 2-ring plane (ring-off-plane)
// round-borders (flat_junctions.cpp): a junction chain between two flats is a resolved fillet when its samples
constexpr double kRoundBorderRadius = 1.8;  // cells: ... allow this rounding (a sharp edge along a lattice axis allows up to ~sqrt 3, round-chains' note; build/bench/bench_fillets)
constexpr int kRoundBorderRings = 3;        // rings searched for the chain's second flat (6 paired flats across narrow faces: bench_compare --quick cad-part 128 +8 %)
// --- crease fit (press time)
constexpr int kCreaseRings = 2;            // rings from a junction whose curved vertices are placed (the chamfer's width)
constexpr int kCreaseFitRings = 5;         // rings beyond them the curved side's quadric is fitted on
constexpr double kCreaseResidual = 0.04;   // cells RMS: the fit is trusted up to this (a smooth side fits to ~0.02)
constexpr int kCreaseRounds = 4;           // rounds of fit and re-press (the placement settles in 3-4)
// --- sharpening (Section 5)
constexpr double kMinAngle = 10;           // degrees: planes meeting at less are not intersected (the line is ill-conditioned)
constexpr double kMaxMove = 2;             // cells: farthest a new vertex may move from where it was inserted
constexpr int kChainIterations = 10;       // bilaplacian iterations along the new feature chains
constexpr int kMinCurved = 25;             // vertices: smaller curved patches are chamfer leftovers and join a flat
constexpr int kStripRings = 2;             // rings: curved strips this thin between flats join a flat (strips)
constexpr int kCurvedFitRings = 6;         // rings of a curved side's quadric (tangent-planes)
constexpr double kCurvedFitResidual = 0.05;  // cells RMS: the curved side's quadric is trusted up to this
constexpr int kSnapRings = 8;              // rings searched for the flats around a curved band (snap)
constexpr double kSnapTolerance = 0.05;    // cells: the flats' solid explains a stick within this (snap)
constexpr double kSnapShare = 0.95;        // share of a band's sticks the flats' solid must explain (snap)
constexpr double kWallThickness = 24;      // cells: a rim between two opposite flats this close is a wall (walls)
constexpr int kFinalCreaseRings = 2;       // as kCreaseRings, once the regions are final (final-crease)
constexpr int kFinalCreaseFitRings = 5;    // as kCreaseFitRings
constexpr double kFinalCreaseResidual = 0.04;  // as kCreaseResidual
constexpr double kFinalCreaseMaxMove = 0.3;    // cells along the stick: the final placement only corrects
// --- round chains (Section 5's chains; sharpen_chains.cpp): a chain stays round when its samples allow
constexpr double kRoundRadius = 0.85;   // cells: ... a fillet this large (build/bench/bench_fillets: sharp edges allow <= 0.46, r = 0.5 <= 0.69, r = 1 >= 1.0)
constexpr double kRoundEvidence = 0.15;  // cells: ... and demand one: a sample this deep inside both planes (bench_fillets r = 1: >= 0.23; bench_compare --quick: sharp CAD <= 0.14)

}  // namespace voxpress::detail
