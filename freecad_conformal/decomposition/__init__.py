"""Decomposition of solids into support-free sub-parts and their build order."""
