"""Experiment benchmarks: whole experiment files on the cores and through the graph, adaptive
sampling against fixed counts, the progress line's estimate, and what reading an experiment
file costs. Questions asked of finished runs are in studies/."""
