"""experiment_manager: runs the experiments over the graph and records them.

So far: `recording`, the MCAP recorder in the ROS 2 profile. The manager node, the experiment
file and the four experiment types arrive with issue 4's next steps.
"""
