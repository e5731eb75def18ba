"""Graph benchmarks: what DDS, rclpy's executors, message conversion and the recording add to
a call and to an iteration, against the cores in the same run."""
