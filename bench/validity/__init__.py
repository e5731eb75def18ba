"""Validity benchmarks: the staged FCL check against the naive reference, and what the
gripper and the part's roll decide."""
