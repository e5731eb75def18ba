"""pick_common: what every package of the picking-feasibility graph shares.

Pure modules (no rclpy, no PyBullet, no FCL): `errors` (the error hierarchy, the checks and
their limits), `containers` (container specs and the packing rule), `parts` (part specs and
their collision geometry, with trimesh), `specs` (scene and vibration specs), `states` (part
snapshots, settle reports, progress). `conversions` maps the shared messages to and from
those types; `node_runner` is what every node's process shares (parameters, error answers,
watching a call's servers, main()).
"""
