"""Benchmarks: scripts that print figures, with ratios against a baseline measured in the same
run (never timed assertions in tests). Run from the top of the workspace, by area:

    tools/ws python -m bench.world.bench_world          # world/: PyBullet physics and its cost
    tools/ws python -m bench.validity.bench_validity    # validity/: the staged FCL checks
    tools/ws python -m bench.experiment.bench_experiment FILE   # experiment/: whole runs
    tools/ws python -m bench.graph.bench_calls          # graph/: what DDS and rclpy add

Each script's docstring says what it measures and how to call it; `paper_case` holds what
several share (a worker's nodes, a full run's working time; the test case's files and a run on
the cores are studies.cases'). `make bench` runs bench_world and bench_validity, each timing
against a baseline measured in the same run. Benchmarks call public names only. Their figures
are in docs/benchmarks.md. What answers a question (the physics studies, decisions on few runs,
replays, run comparisons) is in studies/, with a test each; re-deciding a finished run is the
`decide` command.
"""
