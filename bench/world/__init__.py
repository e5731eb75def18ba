"""World benchmarks: the PyBullet world on its own (drops, settles, vibrations, feeds), its
cost and whether its answers have converged (time step, solver)."""
