"""Benchmarks: scripts that print figures, with ratios against a baseline measured in the same
run (never timed assertions in tests). Run from the top of the workspace, by area:

    tools/ws python -m bench.world.bench_world          # world/: PyBullet physics and its cost
    tools/ws python -m bench.validity.bench_validity    # validity/: the staged FCL checks
    tools/ws python -m bench.experiment.bench_experiment FILE   # experiment/: whole runs
    tools/ws python -m bench.graph.bench_calls          # graph/: what DDS and rclpy add

Each script's docstring says what it measures and how to call it; `paper_case` holds what
several share (the paper's test-case files, a variant of one, a run on the cores, a worker's
nodes). Benchmarks call public names only. Their figures are in docs/benchmarks.md. Studies of
finished runs (decisions on few runs, replays, run comparisons) are in studies/, with a test
each; re-deciding a finished run is the `decide` command.
"""
