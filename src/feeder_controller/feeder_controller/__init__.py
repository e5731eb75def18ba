"""feeder_controller: the feeder and vibrating table's optimal-range policy.

The core (`policy`) never imports rclpy; `feeder_controller_node` is the thin ROS 2 node that
applies it and commands the world.
"""
