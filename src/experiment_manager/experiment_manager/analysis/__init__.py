"""What a run measured and what it means: the rows an iteration records (`rows`) and the
result files they are written to and read back from (`results`), the metrics of each
experiment (`metrics`), the verdicts against the requirements (`verdicts`) and their wording
(`wording`), the HTML report (`report`) and its scene pictures (`pictures`). No rclpy."""
