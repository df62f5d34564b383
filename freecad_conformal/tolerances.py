"""Named tolerances, each with the reason for its value (all lengths in mm, angles in rad)."""

#: OCC's own confusion distance (Precision::Confusion, 1e-7 mm): two points closer than this
#: are the same point for OpenCASCADE, so nothing we compute can be finer.
OCC_CONFUSION = 1e-7

#: Default chord tolerance for turning exact section curves into polygons for path planning.
#: 1 µm is well below any deposition bead (>= 0.1 mm) yet keeps polygons small.
DEFAULT_CHORD_TOLERANCE = 1e-3

#: A section plane this close to a face or vertex is nudged off it by this much (mm) so
#: the cut is well defined; 1e-6 mm changes a section's area by far less than 1e-9 relative
#: for any part larger than 1 mm, the accuracy asked of exact sections.
SECTION_NUDGE = 1e-6

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
