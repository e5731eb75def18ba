"""Experiment benchmarks: whole experiment files on the cores and through the graph, adaptive
sampling against fixed counts, and what a finished run's directory says."""
