"""pick_sim_world: the PyBullet world of the picking-feasibility graph.

The core never imports rclpy: `world` (the World facade and its state) delegates to `bodies`
(building the scene), `spawning` (where new parts appear), `tray` (the vibrating table's
motion), `stepping` (stepping until the parts rest) and `camera` (pictures); `config` holds the
physics settings and their limits. `conversions` maps the scene and markers to messages;
`world_node` is the thin ROS 2 node around it. The only package that imports PyBullet.
"""
