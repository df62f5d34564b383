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
