"""pick_sim_world: the PyBullet world of the picking-feasibility graph.

The core (`world`, `parts`, `containers`, `config`) never imports rclpy; `world_node` is the
thin ROS 2 node around it.
"""
