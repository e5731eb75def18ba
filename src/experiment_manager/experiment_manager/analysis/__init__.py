"""What a run measured and what it means: the rows an iteration records (`rows`) and the
result files they are written to and read back from (`results`), the metrics of each
experiment (`metrics`, `sensitivity`, with the decision rules of `decisions`), summary.json as
one typed, versioned model with its published schema (`summary`), the verdicts against the
requirements (`verdicts`) and their wording (`wording`, `headlines`), why parts were turned
down (`stages`), the report (`report/`, a module per section) and its scene pictures
(`pictures`, `part_sheet`). No rclpy."""
