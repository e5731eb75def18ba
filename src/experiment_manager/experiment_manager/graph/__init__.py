"""The ROS graph side of the manager: the `experiment_manager` node and its `run_experiment`
action (`experiment_manager_node`), one run from request to report (`session`), a worker
reached over services and actions (`graph_backend`), and the MCAP recording (`recording`,
`topic_recorder`)."""
