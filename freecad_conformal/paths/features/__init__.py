"""Conformal feature generators on faces: rods, shells, patterns, channels (METHODS section 1)."""
