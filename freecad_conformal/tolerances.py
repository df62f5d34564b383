"""Named tolerances, each with the reason for its value (all lengths in mm, angles in rad).

OpenCASCADE's own values (Part.Precision: confusion 1e-7 mm, angular 1e-12 rad) are read from
OCC where a shape is at hand (geometry/solids.occ_confusion); this module stays pure."""

#: Default chord tolerance for turning exact section curves into polygons for path planning.
#: 1 µm is well below any deposition bead (>= 0.1 mm) yet keeps polygons small.
DEFAULT_CHORD_TOLERANCE = 1e-3

#: Areas below this (mm²) are treated as empty sections: slivers left by tangencies.
MIN_SECTION_AREA = 1e-9

#: Tool-tip deviation allowed when linearising moves for the post-processor (mm).
DEFAULT_LINEAR_TOLERANCE = 0.01

#: Tool-axis deviation allowed when linearising rotary moves (rad): 0.05° keeps the tip of a
#: 50 mm long tool within ~0.04 mm of its path.
DEFAULT_ANGULAR_TOLERANCE = 0.05 * 3.141592653589793 / 180.0

#: Two build directions within this angle (rad, 1°) are one direction: the decomposition
#: merges them (concurrent sub-parts) and the build order treats their layers as one stack.
SAME_DIRECTION_ANGLE = 1.0 * 3.141592653589793 / 180.0

#: A point this close (mm) to a sub-part's base level is on it. Base levels come from the
#: B-rep's own vertices, so they agree to rounding; 0.1 µm is far below any layer.
BASE_LEVEL_TOLERANCE = 1e-4

#: Slack when testing rotary limits and reachability (rad / unit vector), so values computed
#: as exactly the limit are not rejected through rounding.
LIMIT_SLACK = 1e-9

#: Floating-point slack for a computed value that should land exactly on a bound or a whole
#: count (a height over a step, a tilt over a pitch, a cosine of ±1): such values carry a few
#: ulps of error; 1e-9 on values of order 1 is far above that and far below any user setting.
ROUNDING_SLACK = 1e-9

#: Unit vectors whose |dot| is within this of 1 are parallel (about 4.5e-5 rad apart).
PARALLEL_COS_SLACK = 1e-9

#: A vector shorter than this has no direction. Valid input gives exact zeros here, rounding
#: leaves ~1e-16, so the value only has to sit between the two.
ZERO_LENGTH = 1e-12

#: Path points closer than this (mm) are the same point (moves of zero length). Far below
#: OCC's 1e-7 mm confusion, so only points that are equal to rounding merge.
COINCIDENT_POINTS = 1e-9

#: Largest move of a `wrap` rotary axis in one block (rad). A wrapping controller takes the
#: short way between two angles in [0, 360), so a block must turn less than half a turn;
#: 90° keeps far from the ambiguous 180° even after the four decimals of the G-code.
WRAP_MAX_STEP = 0.5 * 3.141592653589793

#: A tool axis whose length differs from 1 by more than this is refused rather than
#: normalised: 1e-6 is what a unit vector written with 7 significant digits keeps, while a
#: larger error means the numbers are not a direction (normalising would hide a bug).
AXIS_UNIT_TOLERANCE = 1e-6

#: A floor for divisors that may be exactly zero (a zero-length chord, a degenerate face):
#: every real length, area or sine is far larger, so it never changes a result; it only keeps
#: the division finite where the numerator is zero too.
DIVISION_GUARD = 1e-300

#: A floor for a quantity whose reciprocal is multiplied later: 1/1e-30 stays finite after a
#: few products (1/1e-300 would overflow to inf and turn 0·inf into NaN).
RECIPROCAL_GUARD = 1e-30
