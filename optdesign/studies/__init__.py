"""Studies: solve a problem, trace Pareto fronts, benchmark solvers."""
