"""pick_validity: the staged grasp checks of the picking-feasibility graph, with python-fcl.

The core (`config`, `geometry`, `validity`) never imports rclpy; `validity_node` is the thin
ROS 2 node around it.
"""
