"""Running experiments: what a worker must do (`backend.Backend`; `local_backend` runs it on
this process's cores), one iteration of each experiment type (`procedures`), the scheduler that
spreads iterations over workers (`scheduler`), adaptive sampling's stopping rules (`sampling`)
and the cost of each kind of iteration (`estimate`). No rclpy."""
