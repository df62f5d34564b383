"""Decomposition, build order, layers per sub-part, rotary (unrolled) planning."""
