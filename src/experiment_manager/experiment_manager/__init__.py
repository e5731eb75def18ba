"""The experiment manager: runs the picking-feasibility experiments over the graph, records
them and decides. Its subpackages, each depending only on those listed before it:

- `experiment_file`: the experiment file (its schema, loading with errors that name the key,
  and the plan: the iterations a file asks for, with their seeds);
- `analysis`: what a run measured and what it means (rows, result files, metrics, verdicts,
  their wording, the report and its pictures);
- `running`: running experiments (the iteration procedures, the scheduler over workers,
  adaptive sampling, cost estimates, and the backends: local cores or one graph worker);
- `graph`: the ROS graph side (the experiment_manager node, a run's session, the graph
  backend, the MCAP recording and topic recorder);
- `commands`: the command line (`run`, `replay`, and what `run` needs to start and claim a
  graph of processes).
"""
